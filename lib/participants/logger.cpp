#include "participants/logger.h"

#include <cinttypes>

#include "core/error.h"

namespace rths::participants {

using lockstep::StepMailbox;

Logger::Logger(lockstep::RunIdentity id, lockstep::Timing timing, lcm::LCM* lcm,
               const std::string& log_path, const std::string& csv_path)
    : Participant("logger", std::move(id), timing, lcm) {
  log_ = new lcm::LogFile(log_path, "w");
  if (!log_->good()) {
    delete log_;
    log_ = nullptr;
    throw Error(log_path, "cannot open the event log for writing");
  }
  // A buffer far larger than one step's events: stdio never flushes part of a step on its own,
  // so a killed logger leaves a log that ends on a step boundary.
  static constexpr std::size_t kBuf = 1 << 20;
  std::setvbuf(log_->getFilePtr(), nullptr, _IOFBF, kBuf);
  csv_ = std::fopen(csv_path.c_str(), "w");
  if (!csv_) throw Error(csv_path, "cannot open the signals CSV for writing");
  std::setvbuf(csv_, nullptr, _IOFBF, kBuf);
  std::fprintf(csv_,
               "k,t_s,r_mm,u_mm,u_ff_mm,u_fb_mm,y_mm,e_mm,f_kN,i_cmd_A,i_eff_A,ground_acc_mm_s2\n");
  lcm_->subscribe(lockstep::kChHandshake, &Logger::OnHandshakeLog, this);
  lcm_->subscribe(lockstep::kChDesired, &Logger::OnDesired, this);
  lcm_->subscribe(lockstep::kChCommand, &Logger::OnCommand, this);
  lcm_->subscribe(lockstep::kChMeasured, &Logger::OnMeasured, this);
  lcm_->subscribe(lockstep::kChCurrent, &Logger::OnCurrent, this);
}

Logger::~Logger() {
  Flush();
  if (csv_) std::fclose(csv_);
  delete log_;  // closes the file
}

void Logger::Flush() {
  if (log_) std::fflush(log_->getFilePtr());
  if (csv_) std::fflush(csv_);
}

void Logger::Write(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  lcm::LogEvent ev;
  ev.eventnum = event_number_++;
  ev.timestamp = rbuf->recv_utime;  // wall clock; sim time travels in the payload (k)
  ev.channel = channel;
  ev.datalen = rbuf->data_size;
  ev.data = rbuf->data;
  if (log_->writeEvent(&ev) != 0) throw Error("logger", "writing the event log failed (disk full?)");
}

void Logger::OnHandshakeLog(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  if (!log_ || hs_.decode(rbuf->data, 0, rbuf->data_size) < 0 || hs_.run_id != id_.run_id) return;
  if (!handshakes_logged_.emplace(hs_.participant, hs_.phase).second) return;
  Guarded(-1, [&] {
    Write(rbuf, channel);
    Flush();
  });
}

// One handler per step channel: log the first copy, then see whether step `next_` is complete.
#define RTHS_LOGGER_HANDLER(Method, box)                                   \
  void Logger::Method(const lcm::ReceiveBuffer* rbuf, const std::string& channel) { \
    if (finished()) return;                                                \
    const auto put = box.Add(rbuf, id_.run_id);                            \
    if (put != std::remove_reference_t<decltype(box)>::Put::kNew) return;  \
    Guarded(box.last_k(), [&] {                                            \
      Write(rbuf, channel);                                                \
      TryAck();                                                            \
    });                                                                    \
  }
RTHS_LOGGER_HANDLER(OnCommand, command_)
RTHS_LOGGER_HANDLER(OnMeasured, measured_)
RTHS_LOGGER_HANDLER(OnCurrent, current_)
#undef RTHS_LOGGER_HANDLER

void Logger::OnDesired(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  if (finished()) return;
  HeardClock(lockstep::SteadyClock::now());
  const auto put = desired_.Add(rbuf, id_.run_id);
  const std::int64_t k = desired_.last_k();
  if (put == StepMailbox<rths::desired_t>::Put::kDuplicate) {
    if (!Stalled(k)) Republish(lockstep::kChAck, ack_cache_, k);  // a re-request of step k
    return;
  }
  if (put != StepMailbox<rths::desired_t>::Put::kNew) return;
  if (InjectDrop(k)) {
    desired_.Forget(k);
    return;
  }
  Guarded(k, [&] {
    Write(rbuf, channel);
    TryAck();
  });
}

void Logger::TryAck() {
  while (running() && next_ < id_.n_steps && !Stalled(next_)) {
    const std::int64_t k = next_;
    const rths::desired_t* d = desired_.Get(k);
    const rths::command_t* c = command_.Get(k);
    const rths::measured_t* m = measured_.Get(k);
    const rths::current_t* i = current_.Get(k);
    if (!d || !c || !m || !i) return;
    MaybeThrow(k);
    std::fprintf(csv_, "%" PRId64 ",%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                 k, static_cast<double>(k) * id_.dt_s, d->r_mm, c->u_mm, c->u_ff_mm, c->u_fb_mm,
                 m->y_mm, d->r_mm - m->y_mm, m->f_kN, i->i_cmd_A, m->current_A,
                 d->ground_acc_mm_s2);
    Flush();
    ack_.run_id = id_.run_id;
    ack_.k = k;
    ack_.participant = name_;
    Answer(lockstep::kChAck, &ack_cache_, k, ack_);
    ++next_;
  }
}

}  // namespace rths::participants
