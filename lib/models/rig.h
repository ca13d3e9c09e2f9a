#pragma once
/// @file One interface for the plant participant's loading system + specimen: the linear rig
/// (Eqs. 28-30 with the MR damper, lib/models/linear_rig.h) or the physics-based rig (models.md
/// section 5, lib/models/servo_physical.h), both with the optional current dynamics (Eq. 40 and
/// the 75 Hz low-pass, lib/models/current_driver.h). Units: mm, kN, A, s (docs/units.md).
///
/// Step indices (docs/lockstep.md): after k calls of Step() the rig is at sample k; y_mm(),
/// f_kN() and current_A() are the sensor readings at t_k, made from the state after holding
/// u_{k-1} and i_{k-1} over [t_{k-1}, t_k). At k = 0 the rig is at rest and current_A() is 0.
///
/// Initial current: with current dynamics, the driver starts at the steady state of the first
/// commanded current i_0 (the current is set before the test starts, as in the lab), so a
/// constant current stays exactly constant and equals the commanded one from k = 1 on.
#include <cstdint>
#include <memory>

#include "scenario/scenario.h"

namespace rths::models {

class Rig {
 public:
  virtual ~Rig() = default;
  /// Sample k -> k+1: holds the command u_mm [mm] and the commanded damper current i_cmd_A [A]
  /// over [t_k, t_{k+1}). Allocates nothing. Throws rths::Error if the integration fails.
  virtual void Step(double u_mm, double i_cmd_A) = 0;
  /// Measured actuator displacement y_k [mm].
  virtual double y_mm() const = 0;
  /// Measured specimen force f_k [kN] (0 without a specimen).
  virtual double f_kN() const = 0;
  /// Effective damper current i_c(t_k) [A] (after Eq. 40 and the low-pass if they are on).
  virtual double current_A() const = 0;
  /// Sample index k (number of Step() calls so far).
  virtual std::int64_t k() const = 0;
  /// true for the "ideal" loading system (plant.kind = "ideal"): Step()'s first argument is then
  /// the desired displacement r_k of the step's *end* (not a command held from its start), and
  /// the plant answers measured_t k from desired_t k (docs/lockstep.md, footnote).
  virtual bool TracksDesired() const { return false; }
  /// "ideal" only: the position at k = 0 (r_0, at rest). Others ignore it (they start at rest at 0).
  virtual void StartAt(double /*x_mm*/) {}
};

/// "ideal" (the pure numerical simulation: the damper model in place of the physical plant): a
/// loading system that tracks perfectly. Step(r_k, i_{k-1}) drives the damper with x(t) linear from
/// r_{k-1} to r_k over [t_{k-1}, t_k] (velocity (r_k - r_{k-1}) / dt) at the current i_{k-1}
/// (through the current dynamics if on), so y_k = r_k exactly and f_k is the damper force at t_k
/// (x = r_k, x' = that velocity).
///
/// The rig that `plant` describes ("linear" | "physical" | "ideal"; specimen "mr_damper" | "none";
/// current_dynamics; cvode_rtol; the damper parameters plant.damper), stepping at dt_s [s].
/// With effects or unmodelled disturbances on (plant.RigMode()), the rig mode of
/// lib/models/effect_rig.h, which needs kind "linear"; otherwise the nominal rigs, unchanged.
/// Throws rths::Error for a bad kind or value.
std::unique_ptr<Rig> MakeRig(const scenario::PlantConfig& plant, double dt_s);

/// plant.specimen: true for "mr_damper", false for "none"; throws rths::Error otherwise.
bool HasDamper(const scenario::PlantConfig& plant);

}  // namespace rths::models
