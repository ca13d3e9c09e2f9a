#include "io/mapped_log_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/core.h>

#include "core/error.h"
#include "io/background_thread.h"
#include "io/event_log.h"
#include "io/reserved_file.h"

namespace rths::io {

namespace {
std::int64_t PageBytes() {
  static const std::int64_t page = ::sysconf(_SC_PAGESIZE);
  return page;
}
}  // namespace

MappedLogFile::MappedLogFile(int fd, std::string path, std::int64_t size_bytes, std::int64_t max_chunk_bytes)
    : fd_(fd),
      path_(std::move(path)),
      size_(size_bytes),
      reserved_end_(size_bytes),
      max_chunk_bytes_(std::clamp(max_chunk_bytes, kFirstChunkBytes, kChunkBytes)) {}

MappedLogFile::~MappedLogFile() {
  Close();
  StopPrefault();
  if (fd_ >= 0) ::close(fd_);
}

void MappedLogFile::Unmap() {
  if (!map_) return;
  ++calls_;
  ::munmap(map_, static_cast<std::size_t>(reserved_end_ - map_start_));
  map_ = nullptr;
}

bool MappedLogFile::Reserve(std::int64_t end) {
  const std::int64_t grow = std::clamp(reserved_end_, kFirstChunkBytes, max_chunk_bytes_);
  const std::int64_t page = PageBytes();
  const std::int64_t new_end = (std::max(end, reserved_end_ + grow) + page - 1) / page * page;
  ++calls_;
  if (::fallocate(fd_, 0, static_cast<off_t>(reserved_end_), static_cast<off_t>(new_end - reserved_end_)) != 0) {
    return false;  // unsupported here, or no room (ENOSPC, EFBIG): write instead
  }
  std::lock_guard<std::mutex> lock(map_mutex_);
  Unmap();
  reserved_end_ = new_end;  // after Unmap, which unmaps up to the former end
  map_start_ = size_ / page * page;
  prefaulted_end_ = map_start_;
  ++calls_;
  void* p = ::mmap(nullptr, static_cast<std::size_t>(reserved_end_ - map_start_), PROT_READ | PROT_WRITE, MAP_SHARED,
                   fd_, static_cast<off_t>(map_start_));
  if (p == MAP_FAILED) return false;
  map_ = static_cast<std::uint8_t*>(p);
  return true;
}

void MappedLogFile::PrefaultInBackground() {
  if (prefaulting_ || mode_ != Mode::kMapped) return;
  stop_prefault_.store(false);
  prefaulting_ = StartBackgroundThread(&prefault_thread_, &MappedLogFile::PrefaultMain, this);
}

void* MappedLogFile::PrefaultMain(void* self) {
  auto* f = static_cast<MappedLogFile*>(self);
  constexpr long kIdleMicros = 1000;
  while (!f->stop_prefault_.load(std::memory_order_acquire)) {
    if (!f->PrefaultSome()) SleepMicros(kIdleMicros);
  }
  return nullptr;
}

bool MappedLogFile::PrefaultSome() {
#ifdef MADV_POPULATE_WRITE
  constexpr std::int64_t kPieceBytes = std::int64_t{64} << 10;  // the most the mutex is held for
  std::lock_guard<std::mutex> lock(map_mutex_);
  if (!map_) return false;
  const std::int64_t page = PageBytes();
  const std::int64_t at = appended_.load(std::memory_order_relaxed) / page * page;
  const std::int64_t from = std::max({prefaulted_end_, at, map_start_});
  const std::int64_t to = std::min({reserved_end_, at + kPrefaultAheadBytes, from + kPieceBytes});
  if (to <= from) return false;
  if (::madvise(map_ + (from - map_start_), static_cast<std::size_t>(to - from), MADV_POPULATE_WRITE) != 0 &&
      errno == EINVAL) {
    stop_prefault_.store(true);  // this kernel has no MADV_POPULATE_WRITE: Append faults as before
    return false;
  }
  prefaulted_end_ = to;
  return true;
#else
  stop_prefault_.store(true);
  return false;
#endif
}

void MappedLogFile::StopPrefault() {
  if (!prefaulting_) return;
  stop_prefault_.store(true, std::memory_order_release);
  ::pthread_join(prefault_thread_, nullptr);
  prefaulting_ = false;
}

std::string MappedLogFile::WriteAll(const void* data, std::size_t size) {
  bool cut_back = false;
  std::string why = AppendWhole(fd_, path_, size_, data, size, &calls_, &cut_back);
  if (cut_back) reserved_end_ = size_;
  return why;
}

std::string MappedLogFile::Append(const void* data, std::size_t size) {
  if (mode_ == Mode::kClosed) return fmt::format("writing {} failed: the file is closed", path_);
  const std::int64_t end = size_ + static_cast<std::int64_t>(size);
  if (mode_ == Mode::kMapped && end > reserved_end_ && !Reserve(end)) {
    std::lock_guard<std::mutex> lock(map_mutex_);
    Unmap();
    mode_ = Mode::kWrite;
  }
  if (mode_ == Mode::kWrite) {
    if (std::string why = WriteAll(data, size); !why.empty()) return why;
    size_ = end;
    reserved_end_ = std::max(reserved_end_, size_);
    return {};
  }
  std::uint8_t* at = map_ + (size_ - map_start_);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  const std::size_t head = std::min<std::size_t>(4, size);
  std::memcpy(at + head, bytes + head, size - head);
  std::atomic_thread_fence(std::memory_order_release);  // the sync word last: it commits the rest
  std::memcpy(at, bytes, head);
  size_ = end;
  appended_.store(end, std::memory_order_relaxed);
  return {};
}

void MappedLogFile::CutBack(std::int64_t size_bytes) {
  if (size_bytes >= size_) return;
  // The cut's first word zero at once: a kill before Close() leaves a log that ends there.
  if (map_ && size_bytes >= map_start_) {
    std::memset(map_ + (size_bytes - map_start_), 0, static_cast<std::size_t>(std::min<std::int64_t>(4, size_ - size_bytes)));
  }
  size_ = size_bytes;
  if (mode_ == Mode::kWrite) {
    ++calls_;
    if (::ftruncate(fd_, static_cast<off_t>(size_)) == 0) reserved_end_ = size_;
  }
}

std::string MappedLogFile::Close() {
  if (mode_ == Mode::kClosed) return {};
  StopPrefault();
  mode_ = Mode::kClosed;
  Unmap();
  if (reserved_end_ == size_) return {};
  ++calls_;
  if (::ftruncate(fd_, static_cast<off_t>(size_)) != 0) {
    return fmt::format("cutting {} back to {} bytes failed: {}", path_, size_, std::strerror(errno));
  }
  reserved_end_ = size_;
  return {};
}

std::int64_t TrimZeroTail(const std::string& path) {
  // Reserved space ends the file in zero bytes; a log that does not end in a zero word has none,
  // and is not read through a second time (the supervisor calls this after every run).
  {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : 0;
    if (size >= 4) {
      char last[4] = {1, 1, 1, 1};
      in.seekg(size - 4);
      in.read(last, 4);
      if (in && (last[0] | last[1] | last[2] | last[3]) != 0) return 0;
    }
  }
  std::int64_t end = -1;
  {
    EventLogReader reader(path);
    LogEvent ev;
    while (reader.Next(&ev)) {
    }
    if (!reader.zero_tail()) return 0;
    end = static_cast<std::int64_t>(reader.zero_tail_at_byte());
  }
  const std::int64_t size = static_cast<std::int64_t>(std::filesystem::file_size(path));
  if (::truncate(path.c_str(), static_cast<off_t>(end)) != 0) {
    throw Error(path, fmt::format("cannot cut the reserved space past byte {}: {}", end, std::strerror(errno)));
  }
  return size - end;
}

}  // namespace rths::io
