#pragma once
/// @file procs/controller's participant: the outer-loop tracking controller.
/// Step k: desired_t k (r_k and derivatives) + measured_t k (y_k)  ->  command_t k (u_k),
/// held by the plant over [t_k, t_{k+1}). See docs/lockstep.md.
#include <memory>

#include "control/tracking_controller.h"
#include "participants/step_participant.h"
#include "rths/command_t.hpp"
#include "scenario/scenario.h"

namespace rths::participants {

class Controller final : public DesiredMeasuredParticipant<rths::command_t> {
 public:
  Controller(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, lockstep::Faults faults = {});

 protected:
  void Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
               rths::command_t* out) override;

 private:
  std::unique_ptr<control::TrackingController> law_;
};

}  // namespace rths::participants
