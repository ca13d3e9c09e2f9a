#include "lockstep/step_participant.h"

#include <algorithm>

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
        if (following()) {
          KeepAsHeld(in);
          computed_held_ = false;
        }
      }
      if (!Complete(k)) return;
      PublishStep(k);
      answered = true;
    });
    if (!answered) return;
    if (following()) ledger_.Mark(k, computed_held_);
    ++next_;
  }
}

void StepParticipant::OnFollowStart() { ledger_.Size(id_.n_steps); }

void StepParticipant::BeforeFollowInput(Channel /*channel*/, std::int64_t k) {
  ledger_.Heard();
  latest_seen_ = std::max(latest_seen_, k);
  // Steps up to k - kFollowLag will get nothing more: answer them, holding what is missing.
  while (running() && next_ < id_.n_steps && next_ <= k - kFollowLag && !Stalled(next_)) {
    AnswerWithHolds(next_);
    TryStep();  // the steps after it whose inputs are all in
  }
}

void StepParticipant::OnFollowEnd() {
  // The feed has ended: a step of which something arrived is answered; the rest were never seen.
  while (running() && next_ < id_.n_steps && next_ <= latest_seen_ && !Stalled(next_)) {
    AnswerWithHolds(next_);
    TryStep();
  }
}

void StepParticipant::KeepAsHeld(const StepInputs& in) {
  if (in.desired && in.desired != &held_.desired) held_.desired = *in.desired;
  if (in.command && in.command != &held_.command) held_.command = *in.command;
  if (in.measured && in.measured != &held_.measured) held_.measured = *in.measured;
  if (in.current && in.current != &held_.current) held_.current = *in.current;
}

void StepParticipant::AnswerWithHolds(std::int64_t k) {
  if (computed_ == k) {
    StepInputs in;
    bool held = false;
    const RoleRow& row = *wiring_.row;
    for (int i = 0; i < row.n_inputs(); ++i) {
      const std::int64_t j = k + row.inputs[i].offset;
      if (!Exists(j)) continue;
      const bool have = boxes_.Has(row.inputs[i].channel, j);
      held = held || !have;
      switch (row.inputs[i].channel) {
        case kDesired: in.desired = have ? boxes_.desired.Get(j) : &held_.desired; break;
        case kCommand: in.command = have ? boxes_.command.Get(j) : &held_.command; break;
        case kMeasured: in.measured = have ? boxes_.measured.Get(j) : &held_.measured; break;
        case kCurrent: in.current = have ? boxes_.current.Get(j) : &held_.current; break;
        default: break;
      }
    }
    bool ok = false;
    Guarded(k, [&] {
      MaybeFault(k);
      ok = ComputeStep(k, in);
    });
    if (!ok || !running()) return;
    ++computed_;
    KeepAsHeld(in);
    computed_held_ = held;
  }
  // Computed (now, or before from complete inputs while what the step waits for was lost).
  Guarded(k, [&] { PublishStep(k); });
  if (!running()) return;
  ledger_.Mark(k, computed_held_);
  ++next_;
}

void StepParticipant::Lacks(std::int64_t k, WantList* out) const {
  if (next_ > k + wiring_.max_barrier_offset()) return;
  for (int i = 0; i < wiring_.n_waits; ++i) {
    const std::int64_t j = next_ + wiring_.waits[i].offset;
    if (Exists(j) && !boxes_.Has(wiring_.waits[i].channel, j)) out->Add(wiring_.waits[i].channel, j);
  }
}

}  // namespace rths::lockstep
