#pragma once
/// @file procs/controller's participant: the outer-loop tracking controller.
/// Step k: desired_t k (r_k and derivatives) + measured_t k (y_k)  ->  command_t k (u_k),
/// held by the plant over [t_k, t_{k+1}). Its wiring is the controller's row of the step table
/// (lockstep/step_table.h, docs/lockstep.md).
#include <memory>

#include "control/tracking_controller.h"
#include "lockstep/step_participant.h"
#include "rths/command_t.hpp"
#include "scenario/scenario.h"

namespace rths::participants {

class Controller final : public lockstep::StepAnswerer<rths::command_t> {
 public:
  /// `wiring`: the run's (WiringOf(s), or a replay's).
  Controller(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
             lockstep::Faults faults = {});

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::command_t* out) override;

 private:
  std::unique_ptr<control::TrackingController> law_;
};

}  // namespace rths::participants
