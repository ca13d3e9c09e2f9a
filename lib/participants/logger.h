#pragma once
/// @file The logger: a lockstep participant that never drops a message (docs/lockstep.md).
///
/// Step k (inputs -> answer):
///   desired_t k, command_t k, measured_t k, current_t k  ->  ack_t k
/// The first copy of every (channel, k) is appended to a standard LCM event log (readable by
/// lcm-logplayer and lcm-spy) as soon as it arrives; re-sent duplicates are not logged. Once all
/// four messages of step k are written, the row k of signals.csv is written, both files are
/// flushed to the kernel, and only then is ack_t k published: the clock cannot advance past a
/// step the logger has not stored. The handshake is logged on its own channel (first copy per
/// participant and phase). After an abort, the files hold every step acknowledged so far.
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "lockstep/runtime.h"
#include "rths/ack_t.hpp"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::participants {

class Logger : public lockstep::Participant {
 public:
  /// Opens `log_path` (LCM event log) and `csv_path` (signals) for writing; throws rths::Error.
  Logger(lockstep::RunIdentity id, lockstep::Timing timing, lcm::LCM* lcm,
         const std::string& log_path, const std::string& csv_path);
  ~Logger() override;

  /// Steps acknowledged so far.
  std::int64_t steps_written() const { return next_; }

 protected:
  void OnDone() override { Flush(); }
  void OnStop() override { Flush(); }

 private:
  void OnHandshakeLog(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnDesired(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnMeasured(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnCurrent(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void Write(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void TryAck();
  void Flush();

  lcm::LogFile* log_ = nullptr;
  std::FILE* csv_ = nullptr;
  std::int64_t event_number_ = 0;
  std::int64_t next_ = 0;  ///< next step to acknowledge
  lockstep::StepMailbox<rths::desired_t> desired_;
  lockstep::StepMailbox<rths::command_t> command_;
  lockstep::StepMailbox<rths::measured_t> measured_;
  lockstep::StepMailbox<rths::current_t> current_;
  lockstep::AnswerCache ack_cache_;
  rths::ack_t ack_{};
  rths::handshake_t hs_{};
  std::set<std::pair<std::string, int>> handshakes_logged_;
};

}  // namespace rths::participants
