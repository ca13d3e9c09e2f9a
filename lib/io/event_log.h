#pragma once
/// @file The LCM event log format (what lcm-logger writes and lcm-logplayer reads), written by our
/// logger without liblcm's stdio writer, so that a write error is seen and a step is one write,
/// and read back by EventLogReader, a bounded reader of our own (liblcm's lcm::LogFile trusts the
/// lengths in the file: a payload length of 0x7FFFFFFF crashes it).
///
/// An event is a 28-byte header then the channel name and the payload, all big-endian:
///   uint32 sync word 0xEDA1DA01 | int64 event number | int64 timestamp [us]
///   | int32 channel length | int32 payload length | channel bytes | payload bytes
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace rths::io {

inline constexpr std::uint32_t kEventSync = 0xEDA1DA01u;
inline constexpr std::size_t kEventHeaderBytes = 28;
/// Longest channel name LCM accepts (LCM_MAX_CHANNEL_NAME_LENGTH).
inline constexpr std::size_t kMaxChannelBytes = 63;

namespace detail {
inline void PutBigEndian(std::uint64_t v, int bytes, std::uint8_t* out) {
  for (int i = 0; i < bytes; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * (bytes - 1 - i)));
}
}  // namespace detail

/// Bytes one event takes in the file.
inline std::size_t EventBytes(std::string_view channel, std::size_t payload_bytes) {
  return kEventHeaderBytes + channel.size() + payload_bytes;
}

/// Appends one event to `out`. Allocation-free once `out` has the capacity (reserve it once).
inline void AppendEvent(std::vector<std::uint8_t>* out, std::int64_t event_number, std::int64_t utime,
                        std::string_view channel, const void* payload, std::size_t payload_bytes) {
  const std::size_t at = out->size();
  out->resize(at + EventBytes(channel, payload_bytes));
  std::uint8_t* p = out->data() + at;
  detail::PutBigEndian(kEventSync, 4, p);
  detail::PutBigEndian(static_cast<std::uint64_t>(event_number), 8, p + 4);
  detail::PutBigEndian(static_cast<std::uint64_t>(utime), 8, p + 12);
  detail::PutBigEndian(channel.size(), 4, p + 20);
  detail::PutBigEndian(payload_bytes, 4, p + 24);
  p += kEventHeaderBytes;
  std::memcpy(p, channel.data(), channel.size());
  if (payload_bytes > 0) std::memcpy(p + channel.size(), payload, payload_bytes);
}

/// Largest payload EventLogReader accepts [bytes]. Our largest message is a few hundred bytes
/// (desired_t of a multi-storey structure: a few kB); LCM's UDP transport caps a message near 4 MB.
inline constexpr std::size_t kMaxPayloadBytes = std::size_t{16} << 20;  // 16 MiB

/// One event as EventLogReader read it.
struct LogEvent {
  std::uint64_t offset_bytes = 0;  ///< where the event's sync word starts in the file
  std::int64_t event_number = 0;   ///< the header's event number
  std::int64_t utime = 0;          ///< the header's timestamp [us] (wall clock of the receiver)
  std::string channel;             ///< 1..kMaxChannelBytes printable ASCII characters
  std::vector<std::uint8_t> data;  ///< the payload, 0..kMaxPayloadBytes bytes
};

/// Reads an LCM event log event by event, from a file or a memory buffer, trusting nothing in it:
/// every event must start with the sync word, its channel length must be 1..kMaxChannelBytes (and
/// the name printable ASCII) and its payload length 0..kMaxPayloadBytes; memory use is bounded by
/// the largest event. Garbage throws rths::Error (where = the file's name, problem "byte N: ...",
/// N the offset of the offending event). A file that ends in the middle of an event (a header,
/// channel or payload cut short, e.g. a run killed while writing) is not an error: Next() returns
/// false and truncated() tells, with the offset where the incomplete event starts; the events
/// before it are complete and usable. Nor is a zero word where an event's sync word should be:
/// space a logger reserved ahead (MappedLogFile) and could not cut back because it was killed,
/// or an event it had not finished storing; Next() returns false and zero_tail() tells.
class EventLogReader {
 public:
  /// Opens `path`. Throws rths::Error (where = path) if it cannot be opened or is empty
  /// ("empty file, not an LCM event log").
  explicit EventLogReader(const std::string& path);
  /// Reads `size_bytes` bytes at `bytes` (not copied: they must outlive the reader); `name` names
  /// the buffer in messages. Throws rths::Error if size_bytes is 0.
  EventLogReader(std::string name, const std::uint8_t* bytes, std::size_t size_bytes);
  ~EventLogReader();
  EventLogReader(const EventLogReader&) = delete;
  EventLogReader& operator=(const EventLogReader&) = delete;

  /// Reads the next event into `*event`. Returns false at the end of the log: a clean end, or an
  /// incomplete last event (then truncated() is true). Throws rths::Error for garbage (see the
  /// class comment) or a read error.
  bool Next(LogEvent* event);

  /// True once Next() met an event cut short by the end of the file.
  bool truncated() const { return truncated_; }
  /// Where the incomplete last event starts [byte offset] (meaningful if truncated()).
  std::uint64_t truncated_at_byte() const { return truncated_at_; }
  /// True once Next() met a zero word where an event should start (the log ends there).
  bool zero_tail() const { return zero_tail_; }
  /// Where that zero word is [byte offset] (meaningful if zero_tail()).
  std::uint64_t zero_tail_at_byte() const { return zero_tail_at_; }
  /// The file's (or buffer's) size [bytes], taken when it was opened.
  std::uint64_t size_bytes() const { return size_; }
  /// Complete events read so far.
  std::int64_t events() const { return events_; }
  /// The file's path, or the buffer's name.
  const std::string& name() const { return name_; }

 private:
  /// Copies up to n bytes at the current offset into out; returns how many it copied.
  std::size_t Read(void* out, std::size_t n);
  /// Throws "<name>: byte <at>: <what>".
  [[noreturn]] void Fail(std::uint64_t at, const std::string& what) const;

  std::string name_;
  std::FILE* file_ = nullptr;
  const std::uint8_t* mem_ = nullptr;
  std::uint64_t size_ = 0, offset_ = 0, truncated_at_ = 0, zero_tail_at_ = 0;
  std::int64_t events_ = 0;
  bool truncated_ = false, ended_ = false, zero_tail_ = false;
};

}  // namespace rths::io
