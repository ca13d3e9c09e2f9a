#pragma once
/// @file The LCM event log format (what lcm-logger writes and lcm-logplayer reads), written by our
/// logger without liblcm's stdio writer, so that a write error is seen and a step is one write.
///
/// An event is a 28-byte header then the channel name and the payload, all big-endian:
///   uint32 sync word 0xEDA1DA01 | int64 event number | int64 timestamp [us]
///   | int32 channel length | int32 payload length | channel bytes | payload bytes
#include <cstdint>
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
  for (char c : channel) *p++ = static_cast<std::uint8_t>(c);
  const auto* src = static_cast<const std::uint8_t*>(payload);
  for (std::size_t i = 0; i < payload_bytes; ++i) p[i] = src[i];
}

}  // namespace rths::io
