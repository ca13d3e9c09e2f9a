#include "lockstep/step_participant.h"

namespace rths::lockstep {

StepParticipant::StepParticipant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm,
                                 Faults faults, const ResolvedRole& wiring)
    : Participant(std::move(name), std::move(id), config, lcm, std::move(faults)), wiring_(wiring) {
  SetAnswerChannel(wiring_.row->answer, &cache_);
  SubscribeInputs(wiring_, &boxes_, [this](Channel channel, std::int64_t k, const lcm::ReceiveBuffer* rbuf) {
    OnInput(channel, k, rbuf);
    TryStep();
  });
}

bool StepParticipant::Gather(std::int64_t k, StepInputs* in) const {
  const RoleRow& row = *wiring_.row;
  for (int i = 0; i < row.n_inputs(); ++i) {
    const std::int64_t j = k + row.inputs[i].offset;
    if (!Exists(j)) continue;
    switch (row.inputs[i].channel) {
      case kDesired: in->desired = boxes_.desired.Get(j); break;
      case kCommand: in->command = boxes_.command.Get(j); break;
      case kMeasured: in->measured = boxes_.measured.Get(j); break;
      case kCurrent: in->current = boxes_.current.Get(j); break;
      default: break;
    }
    if (!boxes_.Has(row.inputs[i].channel, j)) return false;
  }
  return true;
}

bool StepParticipant::Complete(std::int64_t k) const {
  for (int i = 0; i < wiring_.n_waits; ++i) {
    const std::int64_t j = k + wiring_.waits[i].offset;
    if (Exists(j) && !boxes_.Has(wiring_.waits[i].channel, j)) return false;
  }
  return true;
}

void StepParticipant::TryStep() {
  while (running() && next_ < id_.n_steps && !Stalled(next_)) {
    const std::int64_t k = next_;
    StepInputs in;
    if (computed_ == k && !Gather(k, &in)) return;
    bool answered = false;
    Guarded(k, [&] {
      if (computed_ == k) {
        MaybeFault(k);
        if (!ComputeStep(k, in)) return;
        ++computed_;
      }
      if (!Complete(k)) return;
      PublishStep(k);
      answered = true;
    });
    if (!answered) return;
    ++next_;
  }
}

void StepParticipant::Lacks(std::int64_t k, WantList* out) const {
  if (next_ > k + wiring_.max_barrier_offset()) return;
  for (int i = 0; i < wiring_.n_waits; ++i) {
    const std::int64_t j = next_ + wiring_.waits[i].offset;
    if (Exists(j) && !boxes_.Has(wiring_.waits[i].channel, j)) out->Add(wiring_.waits[i].channel, j);
  }
}

}  // namespace rths::lockstep
