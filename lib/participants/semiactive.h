#pragma once
/// @file procs/semiactive's participant: the damper current command.
/// Step k: desired_t k (structure state) + measured_t k (y_k, f_k)  ->  current_t k, held by the
/// plant over [t_k, t_{k+1}): it first shows in measured_t k+1. Its wiring is the semiactive row of
/// the step table (lockstep/step_table.h, docs/lockstep.md).
/// A scheduled current (control::CurrentSchedule: passive-off 0 A, passive-on, a constant, or the
/// pulse of Table 2), or clipped-optimal control (control/clipped_optimal.h: it uses the absolute
/// accelerations of sample k-1 carried by desired_t k and the forces of samples k-1 and k).
#include <memory>
#include <optional>

#include "control/clipped_optimal.h"
#include "control/current_schedule.h"
#include "lockstep/step_participant.h"
#include "rths/current_t.hpp"
#include "scenario/scenario.h"

namespace rths::participants {

class Semiactive final : public lockstep::StepAnswerer<rths::current_t> {
 public:
  /// `wiring`: the run's (WiringOf(s), or a replay's).
  Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
             lockstep::Faults faults = {});

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::current_t* out) override;

 private:
  std::optional<control::CurrentSchedule> schedule_;  ///< scheduled modes
  std::unique_ptr<control::ClippedOptimal> clipped_;  ///< "clipped_optimal"
  double f_prev_kN_ = 0.0;                            ///< force of one damper at step k-1
};

}  // namespace rths::participants
