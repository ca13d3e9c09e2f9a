#include "participants/logger.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <fmt/core.h>

#include "core/error.h"
#include "io/event_log.h"
#include "io/signals_row.h"

namespace rths::participants {

namespace {
constexpr const char* kCsvHeader = io::kSignalsCsvHeader;
constexpr std::size_t kCsvRowMaxBytes = io::kSignalsRowMaxBytes;

int CreateFile(const std::string& path, const char* what, int flags = O_WRONLY) {
  const int fd = ::open(path.c_str(), flags | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(path, fmt::format("cannot create the {}: {}", what, std::strerror(errno)));
  return fd;
}
}  // namespace

std::int64_t StoredBytesPerStep(int n_dof) { return LogBytesPerStep(n_dof) + static_cast<std::int64_t>(kCsvRowMaxBytes); }

std::int64_t LogBytesPerStep(int n_dof) {
  // desired_t: 8 hash + 2x8 (run_id, k) + 7x8 doubles + 4 (n_dof) + 2 n_dof x8; the others are
  // fixed (hash, run_id, k and their doubles); ack_t is not logged.
  const std::int64_t desired = 8 + 16 + 7 * 8 + 4 + 16 * static_cast<std::int64_t>(n_dof);
  const std::int64_t command = 8 + 16 + 3 * 8, measured = 8 + 16 + 3 * 8, current = 8 + 16 + 2 * 8;
  const std::int64_t events = static_cast<std::int64_t>(
      io::EventBytes(lockstep::kChDesired, desired) + io::EventBytes(lockstep::kChCommand, command) +
      io::EventBytes(lockstep::kChMeasured, measured) + io::EventBytes(lockstep::kChCurrent, current));
  return events;
}

Logger::Logger(lockstep::RunIdentity id, lockstep::LockstepConfig config, lcm::LCM* lcm,
               const lockstep::Wiring& wiring, const std::string& log_path, const std::string& csv_path,
               lockstep::Faults faults, int csv_every)
    : StepAnswerer("logger", std::move(id), config, lcm, std::move(faults), wiring.Of("logger")),
      log_path_(log_path),
      csv_path_(csv_path),
      csv_every_(csv_every) {
  if (csv_every_ < 0) throw Error(csv_path_, fmt::format("csv_every = {}: must be >= 0", csv_every_));
  log_ = std::make_unique<io::MappedLogFile>(CreateFile(log_path_, "event log", O_RDWR), log_path_);
  if (csv_every_ > 0) csv_fd_ = CreateFile(csv_path_, "signals CSV");
  if (const std::string why = csv_fd_ < 0 ? std::string()
                                          : Append(csv_fd_, csv_path_, reinterpret_cast<const std::uint8_t*>(kCsvHeader),
                                                   std::strlen(kCsvHeader), &csv_end_);
      !why.empty()) {
    ::close(csv_fd_);
    throw Error(csv_path_, why);
  }
  step_bytes_.reserve(4096);
  if (csv_fd_ >= 0) {
    csv_buf_.reserve(kCsvFlushBytes + kCsvRowMaxBytes);
    csv_reserved_end_ = csv_end_;
    if (const std::string why = FlushCsv(); !why.empty()) {  // reserves the first stretch
      ::close(csv_fd_);
      throw Error(csv_path_, why);
    }
  }
}

Logger::~Logger() {
  if (csv_fd_ >= 0) CloseCsv();  // after a stop without OnStop (an exception): keep the rows
  if (csv_fd_ >= 0) ::close(csv_fd_);
}  // log_ cuts log.lcm back to its last event

std::int64_t Logger::write_calls() const { return write_calls_ + log_->system_calls(); }

std::string Logger::Append(int fd, const std::string& path, const std::uint8_t* data, std::size_t size,
                           std::int64_t* good_end) {
  std::size_t done = 0;
  while (done < size) {
    ++write_calls_;
    const ssize_t n = ::pwrite(fd, data + done, size - done, static_cast<off_t>(*good_end + done));
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const std::string err = n < 0 ? std::strerror(errno) : "no progress (device full?)";
    // Nothing of a half-written event or row may stay behind.
    if (::ftruncate(fd, static_cast<off_t>(*good_end)) != 0) {
      return fmt::format("writing {} failed: {}; cutting it back to {} bytes failed too: {}", path, err,
                         *good_end, std::strerror(errno));
    }
    return fmt::format("writing {} failed: {}", path, err);
  }
  *good_end += static_cast<std::int64_t>(size);
  return {};
}

void Logger::FailWrite(const std::string& why, std::int64_t k) {
  // log.lcm ends on the last written step (it may hold part of step k); the buffered rows are
  // all of written steps: write them (a failed write cuts signals.csv to a whole row).
  log_->CutBack(log_acked_);
  const bool cut_log = log_->Close().empty();
  const bool csv_ok = csv_fd_ < 0 || CloseCsv().empty();
  std::string reason = fmt::format("{} (at step {}; the log and signals.csv end on step {}, the last "
                                   "complete one{})",
                                   why, k, written_ - 1,
                                   !cut_log ? "; cutting the log back failed"
                                   : !csv_ok ? "; signals.csv ends earlier, on a whole row"
                                             : "");
  Fail(rths::kExitOutput, "logger: " + reason, true, k);
}

std::string Logger::AddCsvRow(const char* row, std::size_t size) {
  if (!csv_buffered_) return Append(csv_fd_, csv_path_, reinterpret_cast<const std::uint8_t*>(row), size, &csv_end_);
  csv_buf_.append(row, size);
  return csv_buf_.size() >= kCsvFlushBytes ? FlushCsv() : std::string();
}

std::string Logger::FlushCsv() {
  if (!csv_buf_.empty()) {
    const std::string why = Append(csv_fd_, csv_path_, reinterpret_cast<const std::uint8_t*>(csv_buf_.data()),
                                   csv_buf_.size(), &csv_end_);
    csv_buf_.clear();
    if (!why.empty()) return why;
  }
  // Reserve what the next flush writes (it may exceed kCsvFlushBytes by one row), so that a full
  // disk fails the log's write, never a flush of rows already acknowledged.
  if (csv_reserved_end_ < csv_end_ + static_cast<std::int64_t>(kCsvFlushBytes + kCsvRowMaxBytes)) {
    ++write_calls_;
    const off_t len = static_cast<off_t>(2 * kCsvFlushBytes);
    csv_buffered_ = ::fallocate(csv_fd_, FALLOC_FL_KEEP_SIZE, static_cast<off_t>(csv_end_), len) == 0;
    csv_reserved_end_ = csv_buffered_ ? csv_end_ + len : csv_end_;
  }
  return {};
}

std::string Logger::CloseCsv() {
  if (csv_closed_ || csv_fd_ < 0) return {};
  csv_closed_ = true;
  std::string why = FlushCsv();
  csv_buffered_ = false;
  if (csv_reserved_end_ > csv_end_) {  // give back the reserved blocks past the last row
    ++write_calls_;
    ::fallocate(csv_fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(csv_end_),
                static_cast<off_t>(csv_reserved_end_ - csv_end_));
    csv_reserved_end_ = csv_end_;
  }
  return why;
}

// Every step is in log.lcm before its ack; the log stays open for the handshake's last messages
// and is cut back to its last event when the logger is destroyed.
std::string Logger::OnDone() { return CloseCsv(); }

void Logger::OnStop() { CloseCsv(); }

void Logger::OnInput(lockstep::Channel channel, std::int64_t k, const lcm::ReceiveBuffer* rbuf) {
  RawRing* raw = channel == lockstep::kDesired    ? &raw_desired_
                 : channel == lockstep::kCommand  ? &raw_command_
                 : channel == lockstep::kMeasured ? &raw_measured_
                 : channel == lockstep::kCurrent  ? &raw_current_
                                                  : nullptr;
  if (!raw) return;
  lockstep::Bytes& slot = (*raw)[k % 4];
  const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
  slot.assign(data, data + rbuf->data_size);  // reuses its capacity after the first steps
}

void Logger::OnHandshakeSeen(const lcm::ReceiveBuffer* rbuf, const rths::handshake_t& msg) {
  if (finished() || !handshakes_logged_.emplace(msg.participant, msg.phase).second) return;
  step_bytes_.clear();
  const std::int64_t utime = start_utime_ < 0 ? rbuf->recv_utime : StepUtime(next_step());
  io::AppendEvent(&step_bytes_, event_number_, utime, lockstep::kChHandshake, rbuf->data,
                  rbuf->data_size);
  if (const std::string why = log_->Append(step_bytes_.data(), step_bytes_.size()); !why.empty()) {
    FailWrite(why, msg.k);
    return;
  }
  ++event_number_;
  log_acked_ = log_->size();  // a whole event between steps: keep it if a later write fails
}

void Logger::OnGo() {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  start_utime_ = std::chrono::duration_cast<std::chrono::microseconds>(now).count();
  StepAnswerer::OnGo();
}

std::int64_t Logger::StepUtime(std::int64_t k) const {
  return start_utime_ + std::llround(static_cast<double>(k) * id_.dt_s * 1e6);
}

bool Logger::Compute(std::int64_t k, const lockstep::StepInputs& in, rths::ack_t* out) {
  if (!WriteStep(k, in)) return false;
  out->participant = name_;
  return true;
}

bool Logger::WriteStep(std::int64_t k, const lockstep::StepInputs& in) {
  const rths::desired_t* d = in.desired;
  const rths::command_t* c = in.command;
  const rths::measured_t* m = in.measured;
  const rths::current_t* i = in.current;
  // The four events of step k in channel order, one write.
  step_bytes_.clear();
  const std::size_t slot = static_cast<std::size_t>(k % 4);
  for (auto [ch, ring] : {std::pair{lockstep::kChDesired, &raw_desired_}, {lockstep::kChCommand, &raw_command_},
                          {lockstep::kChMeasured, &raw_measured_}, {lockstep::kChCurrent, &raw_current_}}) {
    const lockstep::Bytes& r = (*ring)[slot];
    io::AppendEvent(&step_bytes_, event_number_++, StepUtime(k), ch, r.data(), r.size());
  }
  if (const std::string why = log_->Append(step_bytes_.data(), step_bytes_.size()); !why.empty()) {
    FailWrite(why, k);
    return false;
  }
  if (csv_fd_ < 0 || csv_closed_ || k % csv_every_ != 0) {  // this step has no row of signals.csv
    log_acked_ = log_->size();
    ++written_;
    return true;
  }
  char row[kCsvRowMaxBytes + 1];
  const std::size_t n =
      io::FormatSignalsRow(row, k, static_cast<double>(k) * id_.dt_s,
                {d->r_mm, c->u_mm, c->u_ff_mm, c->u_fb_mm, m->y_mm, d->r_mm - m->y_mm, m->f_kN, i->i_cmd_A,
                 m->current_A, d->ground_acc_mm_s2});
  if (const std::string why = AddCsvRow(row, n); !why.empty()) {
    FailWrite(why, k);
    return false;
  }
  log_acked_ = log_->size();
  ++written_;
  return true;
}

}  // namespace rths::participants
