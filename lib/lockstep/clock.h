#pragma once
/// @file The clock authority: owns the step index k (docs/lockstep.md).
///
/// Handshake: REQUEST every 100 ms until every participant of the roster said HELLO with the
/// same scenario hash, step count and dt; then GO (with the roster) and step 0.
/// Step k: the clock publishes desired_t k (its own answer, and the request of step k), then
/// waits for the barrier of step k: measured_t k (plant), command_t k (controller),
/// current_t k (semiactive) and ack_t k (logger: every message of step k is on disk).
/// Silence for `timeout_ms` re-publishes the cached desired_t k (byte-identical: the re-request);
/// participants answer a repeated request from their cache. After `max_attempts` requests the
/// run aborts, naming every participant whose answer of step k is missing. Steps are never
/// skipped: step k+1 is issued only after the barrier of step k.
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "lockstep/runtime.h"
#include "rths/ack_t.hpp"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::lockstep {

/// The participants every run has, in roster order, and the channel of each one's step answer.
struct RosterEntry {
  const char* name;
  const char* channel;  ///< channel of its per-step answer (nullptr for the clock itself)
};
inline constexpr std::array<RosterEntry, 5> kRoster{{{"integrator", kChDesired},
                                                     {"controller", kChCommand},
                                                     {"plant", kChMeasured},
                                                     {"semiactive", kChCurrent},
                                                     {"logger", kChAck}}};

class ClockParticipant : public Participant {
 public:
  ClockParticipant(std::string name, RunIdentity id, Timing timing, lcm::LCM* lcm);

  void Poll(SteadyClock::time_point now) override;

  /// Step currently requested (-1 before GO).
  std::int64_t current_step() const { return k_; }

 protected:
  /// Computes desired_t k into `*out`. `measured_prev` is measured_t k-1 (nullptr for k = 0).
  /// Must not allocate once warmed up (reuse `out`).
  virtual void ComputeDesired(std::int64_t k, const rths::measured_t* measured_prev,
                              rths::desired_t* out) = 0;

  /// Called once per step when its barrier is complete (every message of step k is logged),
  /// before step k+1 is requested. A non-empty return stops the run: ABORT with that reason,
  /// exit code kExitSafety. `desired` is the clock's own desired_t k.
  virtual std::string_view CheckCommitted(std::int64_t /*k*/, const rths::desired_t& /*desired*/,
                                          const rths::measured_t& /*measured*/,
                                          const rths::command_t& /*command*/) {
    return {};
  }

  void OnHandshakeForClock(const rths::handshake_t& msg, SteadyClock::time_point now) override;

 private:
  void OnMeasured(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnCurrent(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnAck(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void CheckBarrier();
  void IssueStep(std::int64_t k);
  void SendGo();
  std::string MissingAnswers(std::int64_t k) const;

  StepMailbox<rths::measured_t> measured_;
  StepMailbox<rths::command_t> command_;
  StepMailbox<rths::current_t> current_;
  StepMailbox<rths::ack_t> ack_;
  AnswerCache desired_cache_;
  rths::desired_t desired_{};

  std::array<bool, kRoster.size()> hello_{};
  std::array<bool, kRoster.size()> bye_{};
  std::int64_t k_ = -1;
  int attempts_ = 0;
  bool done_ = false;
  int done_sends_ = 0;
  SteadyClock::time_point last_send_;
  SteadyClock::time_point start_;
};

}  // namespace rths::lockstep
