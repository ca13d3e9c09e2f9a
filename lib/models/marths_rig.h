#pragma once
/// @file The two sides of the maRTHS benchmark's loop, each as one participant of the lockstep
/// would run it (docs/marths.md "The loop"):
///
/// - the rig (the plant's side): the 2 x 2 control plant stepped as ode4 steps it, the sensor noise,
///   and the virtual specimen's force on the numerical substructure, estimated from the measured
///   strokes through the coupler's inverse and the feedback frame (lib/models/marths_frame.h);
/// - the substructure (the integrator's side): the numerical substructure's Newmark step to t_k
///   under a_g(t_k) and the rig's forces of t_k, and the actuator targets through the coupler.
///
/// Sample k: RigRead (strokes at t_k, forces) -> SubstructureStep -> the compensators -> RigStep
/// (the commands held over [t_k, t_{k+1})). SI inside, strokes in mm.
#include <cstdint>

#include <Eigen/Core>

#include "models/marths_coupler.h"
#include "models/marths_frame.h"
#include "models/marths_plant.h"
#include "models/marths_structure.h"
#include "models/newmark_linear.h"
#include "signal/random.h"

namespace rths::models::marths {

/// The rig's choices (docs/marths.md "Decisions").
struct RigOptions {
  CouplerGeometry geometry;        ///< the coupler's arms (the benchmark's by default)
  double noise_mm = 0.0;           ///< sensor noise standard deviation [mm] (0: off)
  bool identical_noise = true;     ///< the same sample on both channels (as the reference code's seeds)
  std::uint64_t noise_seed = 123;
  InverseForm inverse = InverseForm::kAsWired;
  /// The forces of sample k estimated at t_k (0) or at t_{k-1} (1).
  int force_delay_steps = 0;
  /// The frame's derivatives at the first sample: 0 (Simulink's Derivative block) or from rest.
  bool derivatives_from_rest = false;
};

/// The rig (immutable).
struct MarthsRig {
  MarthsPlant plant;
  FeedbackFrame frame;
  RigOptions options;
};

/// Builds it for `p` at dt_s. Throws rths::Error for a step or option out of range (a coupler
/// geometry CouplerProblem refuses for o.inverse).
MarthsRig MakeMarthsRig(const PlantZpk& p, double dt_s, const RigOptions& o);

/// Per-step state.
struct MarthsRigState {
  MarthsPlantState plant;
  FeedbackFrameState frame;
  signal::GaussianState noise;
  InterfaceForces held{};  ///< force_delay_steps = 1: the last sample's estimate
};

/// At rest (the noise stream at its seed).
MarthsRigState MarthsRigAtRest(const MarthsRig& r);

/// What the rig reports at t_k.
struct RigReading {
  Eigen::Vector2d y_mm = Eigen::Vector2d::Zero();  ///< measured strokes, with noise [mm]
  InterfaceMotion estimate;                         ///< the coupler's inverse of y
  InterfaceForces forces;                           ///< on the numerical DOFs 27, 21, 29
};

/// The reading at t_k (draws this sample's noise and advances the frame's differences: call once
/// per sample, before RigStep). Allocates nothing.
RigReading RigRead(const MarthsRig& r, MarthsRigState* s);

/// t_k -> t_{k+1} with the commands [mm] held. Allocates nothing.
void RigStep(const MarthsRig& r, MarthsRigState* s, const Eigen::Vector2d& u_mm);

/// The numerical substructure and the coupler (immutable).
struct MarthsSubstructure {
  NewmarkLinear numerical;
  CouplerGeometry geometry;
  FrameDofs dofs;  ///< where the interface is (Structures::dofs)
};

/// What the substructure computes at t_k.
struct SubstructureOutput {
  InterfaceMotion interface;  ///< x = U_x [m], theta = -U_theta [rad] (the frame's sign; DOFs 27, 21)
  ActuatorPair targets;       ///< the coupler's forward map of `interface` [mm]
};

/// One Newmark step to t_k under a_g(t_k) [m/s^2] and the rig's forces of t_k. Allocates nothing.
SubstructureOutput SubstructureStep(const MarthsSubstructure& m, NewmarkLinearState* s, double ag_m_s2,
                                    const InterfaceForces& f);

}  // namespace rths::models::marths
