#pragma once
/// @file procs/integrator's participant: the numerical substructure and the clock (owns k).
///
/// Step k (docs/lockstep.md): with measured_t k-1 in (the barrier of step k-1), it computes
/// x_k by central difference (Eqs. 1-3) from x_{k-1}, x_{k-2}, the ground acceleration
/// a_g,k-1 and the force f_{k-1} measured at sample k-1 — i.e. x_{k+1} comes from the force
/// measured at step k — and publishes desired_t k: r_k = x_k at the actuator DOF, with
/// r'_k, r''_k, r'''_k by Eqs. 20-22 from the r sequence (identical to the central-difference
/// accelerations), the structure's displacements x_k and absolute accelerations at k-1.
/// In "predefined" mode r_k is read from a history (BLWN or file); derivatives by Eqs. 20-22
/// or, offline, by non-causal central differences of the known record. The integration itself is
/// models::NumericalSubstructure; this participant wires it to the lockstep clock.
#include <optional>
#include <vector>

#include "control/feedforward.h"
#include "lockstep/clock.h"
#include "models/numerical_substructure.h"
#include "safety/monitor.h"
#include "scenario/scenario.h"

namespace rths::participants {

class Integrator final : public lockstep::ClockParticipant {
 public:
  /// `wiring`: the run's (WiringOf(s), or a replay's): the barrier the clock waits for.
  Integrator(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
             lockstep::Faults faults = {});

 protected:
  void ComputeDesired(std::int64_t k, const rths::measured_t* measured_prev,
                      rths::desired_t* out) override;
  /// The safety monitor (docs/safety.md) on every committed step.
  std::string_view CheckCommitted(std::int64_t k, const rths::desired_t& desired,
                                  const rths::measured_t& measured,
                                  const rths::command_t& command) override;

 private:
  const double dt_s_;
  const models::NumericalSubstructure substructure_;
  models::SubstructureState state_;
  std::optional<control::DerivativeRecords> central_;  ///< offline derivatives, if chosen
  control::ExtrapolationState extrapolation_{};
  safety::Monitor safety_;
};

}  // namespace rths::participants
