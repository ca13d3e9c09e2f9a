#include "io/event_log.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::io {

namespace {

std::uint64_t GetBigEndian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

EventLogReader::EventLogReader(const std::string& path) : name_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw Error(path, fmt::format("cannot open the LCM event log ({})", std::strerror(errno)));
  struct stat st {};
  if (::fstat(::fileno(file_), &st) != 0 || !S_ISREG(st.st_mode)) {
    std::fclose(file_);
    file_ = nullptr;
    throw Error(path, "not a regular file, not an LCM event log");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  if (size_ == 0) {
    std::fclose(file_);
    file_ = nullptr;
    throw Error(path, "empty file, not an LCM event log");
  }
}

EventLogReader::EventLogReader(std::string name, const std::uint8_t* bytes, std::size_t size_bytes)
    : name_(std::move(name)), mem_(bytes), size_(size_bytes) {
  if (size_ == 0) throw Error(name_, "empty file, not an LCM event log");
}

EventLogReader::~EventLogReader() {
  if (file_) std::fclose(file_);
}

void EventLogReader::Fail(std::uint64_t at, const std::string& what) const {
  throw Error(name_, fmt::format("byte {}: {}", at, what));
}

std::size_t EventLogReader::Read(void* out, std::size_t n) {
  std::size_t got = 0;
  if (mem_) {
    got = static_cast<std::size_t>(std::min<std::uint64_t>(n, size_ - offset_));
    if (got > 0) std::memcpy(out, mem_ + offset_, got);
  } else {
    got = std::fread(out, 1, n, file_);
    if (got < n && std::ferror(file_)) Fail(offset_ + got, fmt::format("read error ({})", std::strerror(errno)));
  }
  offset_ += got;
  return got;
}

bool EventLogReader::Next(LogEvent* ev) {
  if (ended_) return false;
  const std::uint64_t at = offset_;
  const std::uint64_t left = size_ - offset_;
  auto truncate = [&] {
    truncated_ = true;
    truncated_at_ = at;
    ended_ = true;
    return false;
  };
  if (left == 0) {
    ended_ = true;
    return false;
  }
  std::uint8_t h[kEventHeaderBytes];
  const std::size_t got = Read(h, std::min<std::uint64_t>(left, kEventHeaderBytes));
  std::uint8_t sync[4];
  detail::PutBigEndian(kEventSync, 4, sync);
  constexpr std::uint8_t kZero[4] = {0, 0, 0, 0};
  if (at > 0 && std::memcmp(h, kZero, std::min<std::size_t>(got, 4)) == 0) {  // reserved, never written
    zero_tail_ = true;
    zero_tail_at_ = at;
    ended_ = true;
    return false;
  }
  if (std::memcmp(h, sync, std::min<std::size_t>(got, 4)) != 0) {
    ended_ = true;
    Fail(at, at == 0 ? "no event sync word (not an LCM event log)"
                     : "no event sync word (not an LCM event log, or corrupt)");
  }
  if (got < kEventHeaderBytes) return truncate();  // the header itself is cut short
  const auto channel_bytes = static_cast<std::int32_t>(GetBigEndian(h + 20, 4));
  const auto payload_bytes = static_cast<std::int32_t>(GetBigEndian(h + 24, 4));
  if (channel_bytes < 1 || channel_bytes > static_cast<std::int32_t>(kMaxChannelBytes)) {
    ended_ = true;
    Fail(at, fmt::format("channel name length {} is out of range [1, {}] (corrupt event header)", channel_bytes,
                         kMaxChannelBytes));
  }
  if (payload_bytes < 0 || static_cast<std::size_t>(payload_bytes) > kMaxPayloadBytes) {
    ended_ = true;
    Fail(at, fmt::format("payload length {} is out of range [0, {}] (corrupt event header)", payload_bytes,
                         kMaxPayloadBytes));
  }
  ev->offset_bytes = at;
  ev->event_number = static_cast<std::int64_t>(GetBigEndian(h + 4, 8));
  ev->utime = static_cast<std::int64_t>(GetBigEndian(h + 12, 8));
  ev->channel.resize(static_cast<std::size_t>(channel_bytes));
  const std::size_t got_channel = Read(ev->channel.data(), ev->channel.size());
  for (std::size_t i = 0; i < got_channel; ++i) {
    const auto c = static_cast<unsigned char>(ev->channel[i]);
    if (c < 0x21 || c > 0x7E) {
      ended_ = true;
      Fail(at, fmt::format("channel name byte {} is 0x{:02x}, not printable ASCII (corrupt event header)", i, c));
    }
  }
  if (got_channel < ev->channel.size()) return truncate();
  if (static_cast<std::uint64_t>(payload_bytes) > size_ - offset_) return truncate();
  ev->data.resize(static_cast<std::size_t>(payload_bytes));
  if (Read(ev->data.data(), ev->data.size()) < ev->data.size()) return truncate();  // the file shrank
  ++events_;
  return true;
}

}  // namespace rths::io
