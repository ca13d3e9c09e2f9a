#pragma once
/// @file An append-only file written through a shared memory mapping (the logger's log.lcm).
///
/// Bytes appended are copied into a MAP_SHARED mapping of the file: they are then in the kernel's
/// page cache, as after a write(2), and stay there if the process dies (SIGKILL included), but
/// appending costs a memcpy, not a system call. Space is reserved ahead with fallocate(2) (the
/// file's size grown with it), in pieces that double from kFirstChunkBytes to kChunkBytes, so a
/// store to the mapping never meets a hole (SIGBUS on a full disk). Where a reservation is refused
/// (disk full, file size limit), appends go on as pwrite(2) calls from there, so the file fills up
/// to the last whole append that fits and the failing Append is reported, as with write(2).
///
/// Crash safety: an Append copies its bytes but the first four (an event's sync word) first and
/// stores those four last; a process killed during the copy leaves a zero word where that event's
/// sync word goes. Readers take a zero word at an event's start as the end of the log.
///
/// Close() cuts the file back to the bytes appended. A process killed before Close() leaves the
/// reserved space past them as zero bytes: EventLogReader reads such a log to its last whole
/// event and reports the zero tail (io::TrimZeroTail cuts it off); lcm-logplayer plays the events
/// before it and ends there with "Invalid header after log data".
///
/// Where the file system cannot reserve space (fallocate unsupported), every Append is one
/// pwrite(2), as before this file existed.
#include <pthread.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>

namespace rths::io {

class MappedLogFile {
 public:
  /// Bytes reserved (and mapped) at a time: the first reservation, and the largest.
  static constexpr std::int64_t kFirstChunkBytes = std::int64_t{64} << 10;
  static constexpr std::int64_t kChunkBytes = std::int64_t{4} << 20;

  /// Takes `fd` (open for reading and writing, empty or at `size_bytes`); `path` names it in
  /// messages. Nothing is reserved until the first Append. `max_chunk_bytes` caps the reservation
  /// pieces (kFirstChunkBytes..kChunkBytes): a paced run uses kFirstChunkBytes, because under
  /// mlockall(MCL_FUTURE) mapping a piece faults all of it in at once (a 4 MiB piece stalled the
  /// step 2.8 ms, missing deadlines at every piece; 64 KiB takes tens of microseconds).
  MappedLogFile(int fd, std::string path, std::int64_t size_bytes = 0, std::int64_t max_chunk_bytes = kChunkBytes);
  /// Close() if not closed; the descriptor is closed.
  ~MappedLogFile();
  MappedLogFile(const MappedLogFile&) = delete;
  MappedLogFile& operator=(const MappedLogFile&) = delete;

  /// Appends `size` bytes: all of them, or none ("" or the error, naming the file).
  std::string Append(const void* data, std::size_t size);
  /// Forgets every byte past `size_bytes` (<= size()); Close() cuts the file there.
  void CutBack(std::int64_t size_bytes);
  /// Unmaps and cuts the file to size(); "" or the error. Appends after it fail.
  std::string Close();

  /// Bytes appended (and not cut back) so far.
  std::int64_t size() const { return size_; }
  /// System calls made so far (fallocate, mmap, munmap, pwrite, ftruncate).
  std::int64_t system_calls() const { return calls_; }
  /// False once the file system refused to reserve space: appends are pwrite(2) calls.
  bool mapped() const { return mode_ == Mode::kMapped; }

  /// Bytes a helper thread keeps pre-faulted past size() (PrefaultInBackground).
  static constexpr std::int64_t kPrefaultAheadBytes = std::int64_t{256} << 10;
  /// Starts a helper thread (io::StartBackgroundThread) that keeps the mapping's next
  /// kPrefaultAheadBytes past size() faulted in for writing (madvise MADV_POPULATE_WRITE, Linux
  /// 5.14): the page cache's work for a new page of reserved space (zeroing it, page_mkwrite: about
  /// 4 us per 4 kB page on ext4, a page per 8 steps of the default run) is done on another core
  /// instead of in Append. Content is unchanged (pre-faulting writes nothing). Where the kernel
  /// lacks it, the helper stops at once and Append faults as before. Close() stops it.
  void PrefaultInBackground();

 private:
  enum class Mode { kMapped, kWrite, kClosed };
  /// Reserves the file up to at least `end` (and a chunk more), then maps from the page holding
  /// size() to the new end. False if the file system refused (then appends are written).
  bool Reserve(std::int64_t end);
  void Unmap();  ///< with map_mutex_ held
  static void* PrefaultMain(void* self);
  /// Pre-faults the next piece past the appended bytes; false if there was nothing to do.
  bool PrefaultSome();
  void StopPrefault();
  std::string WriteAll(const void* data, std::size_t size);

  int fd_ = -1;
  std::string path_;
  Mode mode_ = Mode::kMapped;
  std::int64_t size_ = 0;            ///< bytes appended
  std::int64_t reserved_end_ = 0;    ///< the file's size: the end of the reserved space
  std::uint8_t* map_ = nullptr;      ///< the mapped chunk
  std::int64_t map_start_ = 0;       ///< file offset of map_[0]
  std::int64_t calls_ = 0;
  std::int64_t max_chunk_bytes_ = kChunkBytes;
  // The pre-fault helper: map_, map_start_ and reserved_end_ change only with map_mutex_ held
  // while it runs; it reads them, and the bytes appended, under the mutex.
  std::mutex map_mutex_;
  std::atomic<std::int64_t> appended_{0};  ///< size_, for the helper
  std::int64_t prefaulted_end_ = 0;        ///< file offset up to which the mapping is faulted in
  std::atomic<bool> stop_prefault_{false};
  pthread_t prefault_thread_{};
  bool prefaulting_ = false;
};

/// If the log at `path` ends in a zero word where an event should start (a logger killed before it
/// cut back its reserved space), cuts the file there. Returns how many bytes it cut; throws
/// rths::Error if the file cannot be read or cut, or holds garbage before that point. A file whose
/// last four bytes are not all zero has no reserved tail and is not read further (returns 0).
std::int64_t TrimZeroTail(const std::string& path);

}  // namespace rths::io
