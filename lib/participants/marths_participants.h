#pragma once
/// @file The maRTHS benchmark's loop as three participants of the lockstep (marths.enabled;
/// docs/marths.md "Through the lockstep"): the loop of studies/marths_loop.h, split where the
/// reference code's signals cross from one block to the next, with the step table's
/// "same_sample" integrator row (lockstep/step_table.h):
///
///   plant       measured_t k: RigStep with u_{k-1} held over [t_{k-1}, t_k) (k > 0), then RigRead:
///               the strokes y_k,i (y_act_mm, with the sensor noise) and the forces on the numerical
///               DOFs 27, 21, 29 (f_iface [N, N m, N m]); measured_t 0 at rest, at GO.
///   integrator  desired_t k from measured_t k: the Newmark step to t_k under a_g(t_k) and those
///               forces, the targets through the coupler (r_act_mm [mm]); x_mm holds the frame's DOFs'
///               displacements x 1000 (translations [mm], rotations [mrad]).
///   controller  command_t k from desired_t k and measured_t k: control::MarthsCompensators
///               (u_act_mm [mm]).
///
/// The scalars carry actuator 1 (r_mm, u_mm, y_mm; f_kN = 0), for signals.csv and the live
/// monitor's plots; the safety monitor and the live monitor's peaks cover both actuators' arrays.
/// Each step allocates nothing.
#include <vector>

#include "control/feedforward.h"
#include "control/marths_compensator.h"
#include "lockstep/clock.h"
#include "lockstep/step_participant.h"
#include "models/marths_rig.h"
#include "models/newmark_linear.h"
#include "rths/command_t.hpp"
#include "rths/measured_t.hpp"
#include "safety/monitor.h"
#include "scenario/scenario.h"

namespace rths::participants {

/// The scenario's pieces of the loop, built from the data its loader read (no file is opened).
/// The plant: nominal, or the marths.perturbed_plant-th drawn from marths.plant_seed.
models::marths::PlantZpk MarthsPlantOf(const scenario::Scenario& s);
/// The rig's options: plant.noise_y_mm_rms and [marths]'s decisions.
models::marths::RigOptions MarthsRigOptionsOf(const scenario::Scenario& s);
/// a_g(t_k) [m/s^2] for k < n: marths.ground resampled at run.dt_s, times marths.ground_scale.
std::vector<double> MarthsGroundOf(const scenario::Scenario& s, std::size_t n);
/// The compensators: marths.compensator, RoDeAC from marths.rodeac_file, [controller] with
/// marths.model_1 / model_2 for ff and ff_lqg, the nominal plant for mimo_ff.
control::MarthsCompensatorSpec MarthsCompensatorsOf(const scenario::Scenario& s);

/// The integrator and clock of a maRTHS run.
class MarthsIntegrator final : public lockstep::ClockParticipant {
 public:
  /// `wiring` must give the integrator its "same_sample" row (WiringOf does for marths.enabled).
  MarthsIntegrator(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                   const lockstep::Wiring& wiring, lockstep::Faults faults = {});

 protected:
  void ComputeDesired(std::int64_t k, const rths::measured_t* measured, rths::desired_t* out) override;
  std::string_view CheckCommitted(std::int64_t k, const rths::desired_t& desired, const rths::measured_t& measured,
                                  const rths::command_t& command) override;

 private:
  const double dt_s_;
  const models::marths::MarthsSubstructure sub_;
  models::NewmarkLinearState state_;
  const std::vector<double> ag_m_s2_;
  control::ExtrapolationState extrapolation_{};
  safety::Monitor safety_;
};

/// The rig: the 2 x 2 control plant, the sensor noise and the feedback frame.
class MarthsPlant final : public lockstep::StepAnswerer<rths::measured_t> {
 public:
  MarthsPlant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
              lockstep::Faults faults = {});

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::measured_t* out) override;

 private:
  const models::marths::MarthsRig rig_;
  models::marths::MarthsRigState state_;
};

/// The compensators of both actuators.
class MarthsController final : public lockstep::StepAnswerer<rths::command_t> {
 public:
  MarthsController(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                   const lockstep::Wiring& wiring, lockstep::Faults faults = {});

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::command_t* out) override;

 private:
  control::MarthsCompensators compensators_;
};

}  // namespace rths::participants
