#include "io/signals_csv_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/core.h>

#include "core/error.h"
#include "io/background_thread.h"
#include "io/reserved_file.h"

namespace rths::io {

namespace {
/// Space kept reserved past the written rows: a flush's buffer (kFlushBytes and one row more) and
/// every row the queue can hold, so that no row already added meets a full disk.
constexpr std::int64_t kReserveAheadBytes =
    static_cast<std::int64_t>(SignalsCsvWriter::kFlushBytes + (SignalsCsvWriter::kQueueRows + 1) * kSignalsRowMaxBytes);
}  // namespace

SignalsCsvWriter::SignalsCsvWriter(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(path_, fmt::format("cannot create the signals CSV: {}", std::strerror(errno)));
  if (std::string why = WriteAll(kSignalsCsvHeader, std::strlen(kSignalsCsvHeader)); !why.empty()) {
    ::close(fd_);
    throw Error(path_, why);
  }
  buffer_.reserve(kFlushBytes + kSignalsRowMaxBytes);
  reserved_ = true;
  reserved_end_ = end_;
  (void)Flush();  // nothing to write: reserves the first stretch, or finds the file system refuses
  if (!reserved_) return;  // rows are written by Add, one by one
  queue_ = std::make_unique<Row[]>(kQueueRows);
  joinable_ = StartBackgroundThread(&thread_, &SignalsCsvWriter::ThreadMain, this);
  mode_ = joinable_ ? Mode::kQueued : Mode::kDirect;  // no thread: Add writes (the reservation stays)
}

SignalsCsvWriter::~SignalsCsvWriter() { (void)Close(); }

void* SignalsCsvWriter::ThreadMain(void* self) {
  static_cast<SignalsCsvWriter*>(self)->WriterLoop();
  return nullptr;
}

void SignalsCsvWriter::WriterLoop() {
  char row[kSignalsRowMaxBytes + 1];
  std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    if (tail == head) {
      // stop_ is set after the last Add: a head read after seeing it is final.
      if (stop_.load(std::memory_order_acquire) && head_.load(std::memory_order_acquire) == tail) break;
      SleepMicros(kIdleMicros);
      continue;
    }
    for (; tail != head; ++tail) {
      const Row& r = queue_[tail % kQueueRows];
      buffer_.append(row, FormatSignalsRow(row, r.k, r.t_s, r.values));
      tail_.store(tail + 1, std::memory_order_release);
      if (buffer_.size() < kFlushBytes) continue;
      if (std::string why = Flush(); !why.empty()) {
        error_ = std::move(why);
        state_.store(kFailed, std::memory_order_release);
        return;
      }
      if (!reserved_) state_.store(kUnreserved, std::memory_order_release);  // Add takes over
    }
  }
  if (std::string why = Flush(); !why.empty()) {
    error_ = std::move(why);
    state_.store(kFailed, std::memory_order_release);
  }
}

void SignalsCsvWriter::Join() {
  if (!joinable_) return;
  stop_.store(true, std::memory_order_release);
  ::pthread_join(thread_, nullptr);
  joinable_ = false;
}

std::string SignalsCsvWriter::Add(const Row& row) {
  if (mode_ == Mode::kQueued) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    for (;;) {
      if (state_.load(std::memory_order_acquire) != kRunning) {
        Join();  // it has written what it took and stopped: this thread owns the file from here
        if (!error_.empty()) {
          mode_ = Mode::kClosed;
          return error_;
        }
        mode_ = Mode::kDirect;
        break;
      }
      if (head - tail_.load(std::memory_order_acquire) < kQueueRows) {
        queue_[head % kQueueRows] = row;
        head_.store(head + 1, std::memory_order_release);
        return {};
      }
      ++stalls_;  // the writer is behind: let it run
      SleepMicros(50);
    }
  }
  if (mode_ == Mode::kClosed) return error_.empty() ? fmt::format("{}: written to after it was closed", path_) : error_;
  char text[kSignalsRowMaxBytes + 1];
  if (std::string why = WriteAll(text, FormatSignalsRow(text, row.k, row.t_s, row.values)); !why.empty()) {
    error_ = why;
    mode_ = Mode::kClosed;
    return why;
  }
  return {};
}

std::string SignalsCsvWriter::Close() {
  if (mode_ == Mode::kClosed && fd_ < 0) return error_;
  Join();  // the writer flushes every row it took before it stops
  mode_ = Mode::kClosed;
  if (reserved_end_ > end_) {  // give back the reserved blocks past the last row
    calls_.fetch_add(1, std::memory_order_relaxed);
    ::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(end_),
                static_cast<off_t>(reserved_end_ - end_));
    reserved_end_ = end_;
  }
  ::close(fd_);
  fd_ = -1;
  return error_;
}

std::string SignalsCsvWriter::WriteAll(const char* data, std::size_t size) {
  std::int64_t calls = 0;
  std::string why = AppendWhole(fd_, path_, end_, data, size, &calls);
  calls_.fetch_add(calls, std::memory_order_relaxed);
  if (why.empty()) end_ += static_cast<std::int64_t>(size);
  return why;
}

std::string SignalsCsvWriter::Flush() {
  if (!buffer_.empty()) {
    std::string why = WriteAll(buffer_.data(), buffer_.size());
    buffer_.clear();
    if (!why.empty()) return why;
  }
  if (reserved_ && reserved_end_ < end_ + kReserveAheadBytes) {
    calls_.fetch_add(1, std::memory_order_relaxed);
    const std::int64_t len = 2 * kReserveAheadBytes;
    reserved_ = ::fallocate(fd_, FALLOC_FL_KEEP_SIZE, static_cast<off_t>(end_), static_cast<off_t>(len)) == 0;
    if (reserved_) reserved_end_ = end_ + len;
  }
  return {};
}

}  // namespace rths::io
