#pragma once
/// @file The one step loop of every participant but the clock, derived from its row of the step
/// table (lockstep/step_table.h, docs/lockstep.md): it subscribes to its inputs (waking only for
/// those its wiring says), computes its answer of step k once the row's inputs of step k are in,
/// publishes it once everything its step k waits for is in, and says what it lacks when the clock
/// re-requests a step. The role's own computation is a step function given the decoded inputs.
#include <cstdint>
#include <string>

#include "lockstep/participant.h"
#include "lockstep/step_mailboxes.h"
#include "lockstep/wiring.h"

namespace rths::lockstep {

class StepParticipant : public Participant {
 public:
  /// `wiring`: this role in the run's wiring (Wiring::Of(name)); copied.
  StepParticipant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm, Faults faults,
                  const ResolvedRole& wiring);

 protected:
  /// Computes the answer of step k from `in` (the row's inputs of step k; no allocation once warm).
  /// false: no answer (the participant has failed). Exceptions fail the run (kExitInternal).
  virtual bool ComputeStep(std::int64_t k, const StepInputs& in) = 0;
  /// Publishes the answer of step k computed last (Answer(), with run_id and k).
  virtual void PublishStep(std::int64_t k) = 0;
  /// A new message of step k arrived on `channel` (before the step loop runs).
  virtual void OnInput(Channel /*channel*/, std::int64_t /*k*/, const lcm::ReceiveBuffer* /*rbuf*/) {}

  void OnGo() override { TryStep(); }
  void Lacks(std::int64_t k, WantList* out) const override;
  const FollowLedger* follow_ledger() const override { return following() ? &ledger_ : nullptr; }
  void OnFollowStart() override;
  void BeforeFollowInput(Channel channel, std::int64_t k) override;
  void OnFollowEnd() override;

  const StepMailboxes& inputs() const { return boxes_; }
  const ResolvedRole& wiring() const { return wiring_; }
  AnswerCache* cache() { return &cache_; }
  /// The next step to answer.
  std::int64_t next_step() const { return next_; }

 private:
  void TryStep();
  /// Fills `in` with the row's inputs of step k; false if one is missing.
  bool Gather(std::int64_t k, StepInputs* in) const;
  /// Follow mode: computes (if not yet) and publishes step k now, a lost input replaced by the
  /// last one used on its channel (zero-order hold; before any, the message of zeros: at rest).
  void AnswerWithHolds(std::int64_t k);
  /// Follow mode: the inputs of step k just used become the ones a later lost input is held at.
  void KeepAsHeld(const StepInputs& in);
  /// Whether every message step k waits for is in.
  bool Complete(std::int64_t k) const;
  /// The input (channel, k + offset) exists in this run (0 <= k + offset < n_steps).
  bool Exists(std::int64_t j) const { return j >= 0 && j < id_.n_steps; }

  const ResolvedRole wiring_;
  StepMailboxes boxes_;
  AnswerCache cache_;
  std::int64_t next_ = 0;      ///< next step to answer
  std::int64_t computed_ = 0;  ///< next step to compute (next_, or next_ + 1 while waiting to publish)

  // Follow mode only.
  /// A message of step j proves every input of steps up to j - kFollowLag lost if it is missing:
  /// the recorded log holds every message of step k before any of step k + 1, and lcm-logplayer
  /// plays them in order. 2 (not 1) leaves room for a datagram overtaken by one step. Below the
  /// mailboxes' depth, so a message never evicts an input still waited for.
  static constexpr std::int64_t kFollowLag = 2;
  FollowLedger ledger_;
  std::int64_t latest_seen_ = -1;  ///< the latest step of any message of the run
  bool computed_held_ = false;     ///< the answer computed for next_ used a held input
  struct Held {
    rths::desired_t desired{};
    rths::command_t command{};
    rths::measured_t measured{};
    rths::current_t current{};
  } held_;
};

/// A StepParticipant answering with messages of type Msg.
template <class Msg>
class StepAnswerer : public StepParticipant {
 public:
  using StepParticipant::StepParticipant;

 protected:
  /// Computes the answer of step k into `*out` (run_id and k are filled in after).
  virtual bool Compute(std::int64_t k, const StepInputs& in, Msg* out) = 0;

 private:
  bool ComputeStep(std::int64_t k, const StepInputs& in) final { return Compute(k, in, &answer_); }
  void PublishStep(std::int64_t k) final {
    answer_.run_id = id_.run_id;
    answer_.k = k;
    Answer(ChannelName(wiring().row->answer), cache(), k, answer_);
  }

  Msg answer_{};
};

}  // namespace rths::lockstep
