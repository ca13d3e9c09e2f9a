#pragma once
/// @file The clock authority: owns the step index k (docs/lockstep.md).
///
/// Handshake: REQUEST every 100 ms until every participant of the roster said HELLO with the
/// same scenario hash, step count and dt; then GO (with the roster) and step 0.
/// Step k: the clock publishes desired_t k (its own answer, and the request of step k), then
/// waits for the barrier of step k: measured_t k (plant), command_t k (controller),
/// current_t k (semiactive), ack_t k (logger: every message of step k is on disk) and, for a
/// plant that answers command_t k, measured_t k+1: the barrier is derived from the step table
/// (lockstep/wiring.h), as the clock's inputs of step k+1.
/// Silence for `rerequest_ms` (then twice as long each time, up to 1 s) re-requests step k: a
/// repair_t listing the answers it lacks; their owners re-send them from their caches, and
/// whoever lacks an input says so in a repair_t of its own (docs/lockstep.md, "Repair").
/// A step still incomplete after `stall_budget_s` stops the run, naming the participants that
/// neither answered nor said what they lacked (the silent ones) apart from those that only
/// waited. Steps are never skipped: step k+1 is issued only after the barrier of step k.
/// After the last step: DONE until every BYE is in, then CLOSE.
/// Paced (LockstepConfig::pacing, docs/realtime.md): step k is released at GO + k dt of the wall clock,
/// not as soon as step k-1 completes; every step's latency and deadline are accounted.
#include <array>
#include <optional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lockstep/live_feed.h"
#include "lockstep/participant.h"
#include "lockstep/peer_watch.h"
#include "lockstep/step_mailboxes.h"
#include "lockstep/step_table.h"
#include "lockstep/wiring.h"

namespace rths::lockstep {

class ClockParticipant : public Participant {
 public:
  /// `wiring`: the run's wiring (its clock row gives the barrier); copied.
  ClockParticipant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm, const Wiring& wiring,
                   Faults faults = {});

  void Poll(SteadyClock::time_point now, bool idle) override;
  SteadyClock::time_point PollDeadline() const override;

  /// Step currently requested (-1 before GO).
  std::int64_t current_step() const { return k_; }
  const RealtimeStats* realtime() const override { return &rt_; }
  /// What the clock saw of every participant of the roster (its own entry is empty).
  const std::array<PeerObservation, kRosterSize>* peers() const override { return &peers_; }
  SteadyClock::time_point ReleaseAt() const override { return release_; }

  /// The live monitor (lockstep/live_feed.h): the clock's records of the run go to `sink` (in this
  /// process, not owned; it outlives the run), and an abort the sink is asked for stops the run as
  /// an ABORT from "monitor" would. nullptr: none (the default).
  void SetLiveSink(LiveSink* sink) { live_sink_ = sink; }
  /// The records are published on kChMonitor instead (a participant process: a monitor listens to
  /// the run's URL).
  void PublishLive();
  /// The limits the monitor shows the run's peaks against (the safety monitor's).
  void SetLiveLimits(const LiveLimits& limits) { live_limits_ = limits; }
  SteadyClock::duration SpinBeforeRelease() const override {
    return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(timing_.pacing.spin_s));
  }

 protected:
  /// Computes desired_t k into `*out`. `measured` is the clock row's input: measured_t k-1 for the
  /// ordinary row (nullptr for k = 0), measured_t k for "same_sample" (step_table.h; never null).
  /// Must not allocate once warmed up (reuse `out`).
  virtual void ComputeDesired(std::int64_t k, const rths::measured_t* measured,
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
  void OnRepairForClock(const rths::repair_t& msg) override;
  void OnAbortFrom(const std::string& participant, const std::string& reason) override;
  /// The answers of step k the barrier lacks.
  void Lacks(std::int64_t k, WantList* out) const override;

 private:
  void CheckBarrier();
  void IssueStep(std::int64_t k);
  /// Issues step 0: at GO, or ("same_sample") once measured_t 0 is in. Step 0's release is then, and
  /// every later (paced) release counts from it.
  void IssueFirst();
  /// After GO, before step 0 ("same_sample"): re-requests measured_t 0 as the step's re-requests do;
  /// the stall budget stops the run naming the plant.
  void PollFirst(SteadyClock::time_point now, bool idle);
  /// Issues step k_ + 1; an exception from its computation fails the run.
  void IssueNext();
  void SendGo();
  /// Fails the run: step k_ has been incomplete for the whole stall budget.
  void FailStalled(SteadyClock::time_point now);
  /// Before GO: REQUEST every 0.1 s; names who did not say HELLO after the handshake timeout.
  void PollHandshake(SteadyClock::time_point now, bool idle);
  /// After DONE: DONE again until every BYE is in, then CLOSE (also after the stall budget).
  void PollDone(SteadyClock::time_point now, bool idle);
  /// Fails the run: a watched participant has gone (PeerWatch).
  void FailLost(const PeerLoss& loss);
  /// Also counts, per participant, the answers the barrier received and their copies.
  void Count(Channel channel, Put put, std::int64_t k) override;
  /// Counts step k_'s latency and, when paced, whether it met its deadline; false if the miss
  /// policy stopped the run.
  bool AccountStep(SteadyClock::time_point now);
  /// Paced: when step k is released (t0 + k dt).
  SteadyClock::time_point ReleaseOf(std::int64_t k) const;

  /// Whether the barrier item (channel, k + offset) exists in this run.
  bool Exists(std::int64_t j) const { return j >= 0 && j < id_.n_steps; }
  /// Whether `role` gave every answer the barrier of step k_ waits for.
  bool Answered(const ResolvedRole& role) const;

  const Wiring wiring_;
  StepMailboxes boxes_;
  AnswerCache desired_cache_;
  rths::desired_t desired_{};

  std::array<bool, kRosterSize> hello_{};
  PeerWatch watch_;
  /// A participant that exited with kExitPeerAbort stopped on an ABORT (a monitor's, say) that
  /// may still be on its way here: its loss waits a grace (kAbortGraceS, 1 s) for that ABORT,
  /// which then stops the run as an abort, not as a lost participant.
  std::optional<PeerLoss> pending_loss_;
  SteadyClock::time_point pending_loss_until_{};
  std::array<PeerObservation, kRosterSize> peers_{};
  std::array<int, kChannelCodes> owner_{};  ///< roster index of the role answering each channel (-1: none)
  std::array<bool, kRosterSize> bye_{};
  /// Who sent a repair_t for the current step (alive, but lacking inputs).
  std::array<bool, kRosterSize> reported_{};
  std::int64_t k_ = -1;
  /// Offset of the clock row's measured_t input (-1: measured_t k-1; 0: "same_sample").
  int measured_offset_ = -1;
  bool awaiting_first_ = false;  ///< GO sent, step 0 waits for measured_t 0
  int rerequests_ = 0;  ///< re-requests of the current step (or DONEs after the first)
  double typical_step_s_ = 0;  ///< moving average of the steps that needed no re-request [s]
  bool done_ = false;
  SteadyClock::time_point step_since_;  ///< when step k_ (or DONE) was first sent
  SteadyClock::time_point go_at_;  ///< GO; paced: t0, the release of step 0
  /// Paced: the next step's release while waiting for it, else time_point::max().
  SteadyClock::time_point release_ = SteadyClock::time_point::max();
  RealtimeStats rt_;
  std::int64_t consecutive_misses_ = 0;
  /// Publishes live records on kChMonitor through this participant's transport.
  class PublishSink final : public LiveSink {
   public:
    explicit PublishSink(ClockParticipant* clock) : clock_(clock) {}
    void Push(const rths::monitor_t& record) override;

   private:
    ClockParticipant* clock_;
    Bytes bytes_;
  };
  LiveFeed live_;
  LiveSink* live_sink_ = nullptr;
  LiveLimits live_limits_;
  std::unique_ptr<PublishSink> publish_sink_;
  SteadyClock::time_point last_send_;
  SteadyClock::time_point start_;
};

}  // namespace rths::lockstep
