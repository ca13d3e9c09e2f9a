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
  DesiredMeasuredParticipant(std::string name, lockstep::RunIdentity id, lockstep::Timing timing,
                             lcm::LCM* lcm, const char* answer_channel)
      : Participant(std::move(name), std::move(id), timing, lcm), channel_(answer_channel) {
    lcm_->subscribe(lockstep::kChDesired, &DesiredMeasuredParticipant::OnDesired, this);
    lcm_->subscribe(lockstep::kChMeasured, &DesiredMeasuredParticipant::OnMeasured, this);
  }

 protected:
  /// Computes the answer of step k (run_id and k are filled in by the caller). No allocation.
  virtual void Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
                       AnswerMsg* out) = 0;

 private:
  using DesiredBox = lockstep::StepMailbox<rths::desired_t>;

  void OnDesired(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (finished()) return;
    HeardClock(lockstep::SteadyClock::now());
    const auto put = desired_.Add(rbuf, id_.run_id);
    const std::int64_t k = desired_.last_k();
    if (put == DesiredBox::Put::kDuplicate) {
      if (!Stalled(k)) Republish(channel_, cache_, k);  // re-request: same bytes, never recomputed
      return;
    }
    if (put != DesiredBox::Put::kNew) return;
    if (InjectDrop(k)) {
      desired_.Forget(k);
      return;
    }
    TryStep();
  }
  void OnMeasured(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (finished()) return;
    if (measured_.Add(rbuf, id_.run_id) == lockstep::StepMailbox<rths::measured_t>::Put::kNew) TryStep();
  }
  void TryStep() {
    while (running() && next_ < id_.n_steps && !Stalled(next_)) {
      const rths::desired_t* d = desired_.Get(next_);
      const rths::measured_t* m = measured_.Get(next_);
      if (!d || !m) return;
      const std::int64_t k = next_;
      bool ok = false;
      Guarded(k, [&] {
        MaybeThrow(k);
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
