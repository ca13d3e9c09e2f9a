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
#include "io/signals_csv_writer.h"

namespace rths::participants {

namespace {
/// Creates the event log (for reading and writing: it is mapped); throws rths::Error.
int CreateLog(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(path, fmt::format("cannot create the event log: {}", std::strerror(errno)));
  return fd;
}
}  // namespace

std::int64_t StoredBytesPerStep(int n_dof, int n_act, int n_iface) {
  return LogBytesPerStep(n_dof, n_act, n_iface) + static_cast<std::int64_t>(io::kSignalsRowMaxBytes);
}

std::int64_t LogBytesPerStep(int n_dof, int n_act, int n_iface) {
  // Each: 8 hash + 2x8 (run_id, k), its doubles, and 4 bytes per array length with 8 per element
  // (lcmtypes/*.lcm); ack_t is not logged.
  const std::int64_t act = 4 + 8 * static_cast<std::int64_t>(n_act);
  const std::int64_t desired = 8 + 16 + 7 * 8 + 4 + 16 * static_cast<std::int64_t>(n_dof) + act;
  const std::int64_t command = 8 + 16 + 3 * 8 + 4 + act;
  const std::int64_t measured = 8 + 16 + 3 * 8 + act + 4 + 8 * static_cast<std::int64_t>(n_iface);
  const std::int64_t current = 8 + 16 + 2 * 8;
  const std::int64_t events = static_cast<std::int64_t>(
      io::EventBytes(lockstep::kChDesired, desired) + io::EventBytes(lockstep::kChCommand, command) +
      io::EventBytes(lockstep::kChMeasured, measured) + io::EventBytes(lockstep::kChCurrent, current));
  return events;
}

Logger::Logger(lockstep::RunIdentity id, lockstep::LockstepConfig config, lcm::LCM* lcm,
               const lockstep::Wiring& wiring, const std::string& log_path, const std::string& csv_path,
               lockstep::Faults faults, int csv_every, bool paced)
    : StepAnswerer("logger", std::move(id), config, lcm, std::move(faults), wiring.Of("logger")),
      log_path_(log_path),
      csv_path_(csv_path),
      csv_every_(csv_every) {
  if (csv_every_ < 0) throw Error(csv_path_, fmt::format("csv_every = {}: must be >= 0", csv_every_));
  // Paced: small reservation pieces (each faulted in at once under mlockall) and no pre-fault
  // helper (a piece is faulted in by mmap then; without mlockall a page fault costs microseconds
  // of a 500 us period). Unpaced: 4 MiB pieces, pre-faulted on another core.
  log_ = std::make_unique<io::MappedLogFile>(CreateLog(log_path_), log_path_, 0,
                                             paced ? io::MappedLogFile::kFirstChunkBytes
                                                   : io::MappedLogFile::kChunkBytes);
  if (!paced) log_->PrefaultInBackground();
  if (csv_every_ > 0) csv_ = std::make_unique<io::SignalsCsvWriter>(csv_path_);
  step_bytes_.reserve(4096);
}

Logger::~Logger() = default;  // signals.csv gets every row added; log_ cuts log.lcm back to its last event

std::int64_t Logger::write_calls() const { return (csv_ ? csv_->system_calls() : 0) + log_->system_calls(); }

std::int64_t Logger::output_stalls() const { return csv_ ? csv_->stalls() : 0; }

void Logger::FailWrite(const std::string& why, std::int64_t k) {
  // log.lcm ends on the last written step (it may hold part of step k); the rows added are all of
  // written steps: write them (a failed write cuts signals.csv to a whole row).
  log_->CutBack(log_acked_);
  const bool cut_log = log_->Close().empty();
  const bool csv_ok = CloseCsv().empty();
  std::string reason = fmt::format("{} (at step {}; the log and signals.csv end on step {}, the last "
                                   "complete one{})",
                                   why, k, written_ - 1,
                                   !cut_log ? "; cutting the log back failed"
                                   : !csv_ok ? "; signals.csv ends earlier, on a whole row"
                                             : "");
  Fail(rths::kExitOutput, "logger: " + reason, true, k);
}

std::string Logger::CloseCsv() {
  if (!csv_ || csv_closed_) return {};
  csv_closed_ = true;
  return csv_->Close();
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
  if (!csv_ || csv_closed_ || k % csv_every_ != 0) {  // this step has no row of signals.csv
    log_acked_ = log_->size();
    ++written_;
    return true;
  }
  const io::SignalsCsvWriter::Row row{k, static_cast<double>(k) * id_.dt_s,
                                      {d->r_mm, c->u_mm, c->u_ff_mm, c->u_fb_mm, m->y_mm, d->r_mm - m->y_mm, m->f_kN,
                                       i->i_cmd_A, m->current_A, d->ground_acc_mm_s2}};
  if (const std::string why = csv_->Add(row); !why.empty()) {
    FailWrite(why, k);
    return false;
  }
  log_acked_ = log_->size();
  ++written_;
  return true;
}

}  // namespace rths::participants
