#pragma once
/// @file signals.csv written off the step's path: the logger hands each row's numbers to a writer
/// thread through a preallocated single-producer, single-consumer queue, and that thread formats
/// the rows (io::FormatSignalsRow) and writes them kFlushBytes at a time.
///
/// Why: formatting a row (ten doubles at 17 significant digits) costs about a microsecond, as much
/// as the rest of the logger's step; copying its twelve numbers into the queue costs a few
/// nanoseconds (bench-memq prints both, side by side).
///
/// Guarantees (docs/lockstep.md, "Logging"), the same as when the logger formatted the rows itself:
/// - Every row added is written, in order, unless a write fails; a full queue makes Add wait (a
///   counted stall, stalls()), never drops a row.
/// - The writer writes into space reserved ahead with fallocate(2) (enough for the queue, the
///   buffer and the next flush), so a full disk cannot fail the write of a row already added. Where
///   the file system refuses a reservation, the writer thread is stopped once it has written what
///   it took, and every later row is formatted and written by Add itself, one pwrite per row (a
///   full disk then fails that step's Add, as it fails the log's write).
/// - A failed write cuts the file back to its last whole row; the error (naming the file) is
///   returned by the next Add or by Close.
/// - Close() writes every row added and frees the reserved space past the last row. A process
///   killed (SIGKILL) before Close() leaves signals.csv ending on an earlier whole row; the event
///   log is complete regardless (it is written on the step's path).
///
/// The writer thread never competes with the step (io::StartBackgroundThread: SCHED_OTHER, a small
/// stack); it sleeps kIdleMicros when the queue is empty.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <pthread.h>
#include <string>

#include "io/signals_row.h"

namespace rths::io {

class SignalsCsvWriter {
 public:
  /// Rows the queue holds (about 20 ms of the fastest run at about 165 000 steps/s, 200 KB).
  static constexpr std::size_t kQueueRows = 4096;
  /// Bytes of formatted rows written at once.
  static constexpr std::size_t kFlushBytes = 64 * 1024;
  /// How long the writer sleeps when it finds the queue empty [us].
  static constexpr int kIdleMicros = 1000;

  /// The numbers of one row: step, time [s] and the ten signals (io::FormatSignalsRow).
  struct Row {
    std::int64_t k = 0;
    double t_s = 0;
    std::array<double, 10> values{};
  };

  /// Creates `path` (truncating it) and writes the header; reserves space and starts the writer
  /// thread where the file system allows it. Throws rths::Error naming the file.
  explicit SignalsCsvWriter(std::string path);
  /// Close(), errors ignored (a failed write was reported by Add or Close already).
  ~SignalsCsvWriter();
  SignalsCsvWriter(const SignalsCsvWriter&) = delete;
  SignalsCsvWriter& operator=(const SignalsCsvWriter&) = delete;

  /// Adds a row: into the queue, or formatted and written here where no space could be reserved.
  /// "" or the error (a write of this or an earlier row failed; naming the file). No allocation.
  std::string Add(const Row& row);
  /// Writes every row added, stops the writer, frees the reserved space past the last row and
  /// closes the file: "" or the first write error. Later calls return the same; Add fails after it.
  std::string Close();

  /// System calls made so far (pwrite, fallocate, ftruncate), by both threads.
  std::int64_t system_calls() const { return calls_.load(std::memory_order_relaxed); }
  /// Times Add found the queue full and waited for the writer.
  std::int64_t stalls() const { return stalls_; }
  /// True while rows go through the writer thread (space reserved ahead).
  bool threaded() const { return mode_ == Mode::kQueued; }

 private:
  enum class Mode { kQueued, kDirect, kClosed };
  /// What the writer thread reports to Add: running, or stopped on its own.
  enum WriterState : int { kRunning = 0, kUnreserved = 1, kFailed = 2 };

  static void* ThreadMain(void* self);
  void WriterLoop();
  /// Stops the writer once it has written every row in the queue, and waits for it.
  void Join();
  /// Writes `size` bytes at the end: all, or none (the file is cut back to its last whole row).
  std::string WriteAll(const char* data, std::size_t size);
  /// Writes the buffer, then reserves ahead if less than kReserveAheadBytes is left reserved.
  std::string Flush();

  std::string path_;
  int fd_ = -1;
  Mode mode_ = Mode::kDirect;
  std::int64_t end_ = 0;           ///< bytes written, ending on a whole row
  std::int64_t reserved_end_ = 0;  ///< end of the space reserved with fallocate
  bool reserved_ = false;          ///< reservations still granted
  std::string buffer_;             ///< formatted rows not yet written (the writer's)
  std::string error_;              ///< the first write error
  std::int64_t stalls_ = 0;
  std::atomic<std::int64_t> calls_{0};

  std::unique_ptr<Row[]> queue_;
  alignas(64) std::atomic<std::uint64_t> head_{0};  ///< rows added (Add's)
  alignas(64) std::atomic<std::uint64_t> tail_{0};  ///< rows taken (the writer's)
  alignas(64) std::atomic<int> state_{kRunning};
  std::atomic<bool> stop_{false};
  pthread_t thread_{};
  bool joinable_ = false;
};

}  // namespace rths::io
