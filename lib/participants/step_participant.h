#pragma once
/// @file Participants whose answer of step k needs desired_t k and measured_t k: the
/// controller (-> command_t k) and the semiactive law (-> current_t k). docs/lockstep.md.
#include <string>

#include "lockstep/runtime.h"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::participants {

template <class AnswerMsg>
class DesiredMeasuredParticipant : public lockstep::Participant {
 public:
  /// `measured_first`: measured_t k is sent before desired_t k in this run (the plant answers
  /// command_t, and the logger waits for measured_t k+1 before acknowledging step k:
  /// PlantAnswersCommand); then only desired_t wakes this participant, else ("ideal" plant: it
  /// answers desired_t k) only measured_t (docs/lockstep.md, "Wake-ups").
  DesiredMeasuredParticipant(std::string name, lockstep::RunIdentity id, lockstep::Timing timing,
                             lcm::LCM* lcm, lockstep::Faults faults, const char* answer_channel,
                             lockstep::Channel answer_code, bool measured_first)
      : Participant(std::move(name), std::move(id), timing, lcm, std::move(faults)), channel_(answer_channel) {
    using lockstep::Wake;
    SetAnswerChannel(answer_code, &cache_);
    Subscribe(lockstep::kChDesired, [this](const lcm::ReceiveBuffer* rbuf) {
      if (!finished() && Receive(&desired_, lockstep::kDesired, rbuf) == lockstep::Put::kNew) TryStep();
    }, measured_first ? Wake::kOnArrival : Wake::kLater);
    Subscribe(lockstep::kChMeasured, [this](const lcm::ReceiveBuffer* rbuf) {
      if (!finished() && Receive(&measured_, lockstep::kMeasured, rbuf) == lockstep::Put::kNew) TryStep();
    }, measured_first ? Wake::kLater : Wake::kOnArrival);
  }

 protected:
  /// Computes the answer of step k (run_id and k are filled in by the caller). No allocation.
  virtual void Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
                       AnswerMsg* out) = 0;

  /// Inputs of the next answer (desired_t and measured_t of step next_), if it is due by step k.
  void ListMissing(std::int64_t k, lockstep::WantList* out) const override {
    if (next_ > k) return;
    if (!desired_.Get(next_)) out->Add(lockstep::kDesired, next_);
    if (!measured_.Get(next_)) out->Add(lockstep::kMeasured, next_);
  }

 private:
  void TryStep() {
    while (running() && next_ < id_.n_steps && !Stalled(next_)) {
      const rths::desired_t* d = desired_.Get(next_);
      const rths::measured_t* m = measured_.Get(next_);
      if (!d || !m) return;
      const std::int64_t k = next_;
      bool ok = false;
      Guarded(k, [&] {
        MaybeFault(k);
        Compute(k, *d, *m, &answer_);
        answer_.run_id = id_.run_id;
        answer_.k = k;
        Answer(channel_, &cache_, k, answer_);
        ok = true;
      });
      if (!ok) return;
      ++next_;
    }
  }

  const char* const channel_;
  lockstep::StepMailbox<rths::desired_t> desired_;
  lockstep::StepMailbox<rths::measured_t> measured_;
  lockstep::AnswerCache cache_;
  AnswerMsg answer_{};
  std::int64_t next_ = 0;
};

}  // namespace rths::participants
