#pragma once
/// @file procs/semiactive's participant: the damper current command.
/// Step k: desired_t k (structure state) + measured_t k (y_k, f_k)  ->  current_t k, held by the
/// plant over [t_k, t_{k+1}): it first shows in measured_t k+1. See docs/lockstep.md.
/// For now a constant current (passive-off 0 A, passive-on max current, or a given constant);
/// clipped-optimal control (issue 4) implements the same Compute() from the same inputs.
#include "participants/step_participant.h"
#include "rths/current_t.hpp"
#include "scenario/scenario.h"

namespace rths::participants {

/// The current a constant-current mode commands [A] (passive_off: 0, passive_on: max, constant).
double ConstantCurrentA(const scenario::SemiactiveConfig& cfg);

class Semiactive final : public DesiredMeasuredParticipant<rths::current_t> {
 public:
  Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm);

 protected:
  void Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
               rths::current_t* out) override;

 private:
  const double current_A_;
};

}  // namespace rths::participants
