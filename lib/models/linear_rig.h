#pragma once
/// @file The linear rig (plant.kind = "linear" of procs/plant): the linear servohydraulic model
/// (Eqs. 28-30, exact ZOH) moving an MR damper specimen (Eqs. 32-39). Units: mm, kN, s, A.
///
/// One step k -> k+1 with the command u_k [mm] and the damper current i_k [A] held over
/// [t_k, t_{k+1}):
///  - ARKODE (models/ode.h, the default OdeMethod::kErk) integrates the augmented 5-state ODE w = [z (3), y_d, z_bw]:
///        z' = A z + B u_k,  x = C z,  x' = C A z   (the actuator's continuous motion),
///        [y_d, z_bw]' = Eqs. 32-33 at (x, x') with the coefficients at i_k (Eqs. 35-39);
///  - then z_{k+1} is overwritten with the exact ZOH result Phi z_k + Gamma u_k, so the
///    measured displacement is bit-identical to LinearServo's Step(); the damper does not load
///    the linear servo (its effect is inside the identified G).
/// The servo is authoritative for y; the damper states are accurate to the ODE solver's tolerance.
///
/// Current dynamics (optional, lib/models/current_driver.h): the commanded current i_k passes
/// through Eq. 40 and the 75 Hz low-pass; the damper sees the effective current i_c(t), evaluated
/// in closed form inside the step. At a constant current whose driver state is at steady state
/// (SteadyState(i)), i_c = i exactly and the step is bit-identical to the rig without them.
#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/ode.h"
#include "models/servo_linear.h"

namespace rths::models {

/// Immutable description of the rig.
struct LinearRig {
  LinearServo servo;       ///< actuator model and its ZOH matrices (dt = servo.dt_s)
  MrDamperParams damper;   ///< specimen (Table 3)
  bool has_damper = true;  ///< false: no specimen, force is 0
  double rtol = 1e-8;      ///< the ODE solver's relative tolerance (0, 1e-2] (plant.ode_rtol)
  bool current_dynamics = false;  ///< Eq. 40 + low-pass between commanded and effective current
  CurrentDriver driver;           ///< used if current_dynamics

  /// Validates everything (rths::Error on a bad value).
  static LinearRig Make(const models::ServoModel3& actuator, double dt_s, bool has_damper,
                        const MrDamperParams& damper = MrDamperParams::Table3(),
                        double rtol = 1e-8, bool current_dynamics = false,
                        const CurrentDriverParams& driver = {});
};

/// Per-step state at sample k.
struct LinearRigState {
  LinearServoState servo;  ///< z_k = [x, x', x''] of the actuator [mm, mm/s, mm/s^2]
  MrDamperState damper;    ///< y_d, z_bw at t_k [mm]
  CurrentDriverState current;  ///< held command and filter deviation (steady at 0 A at rest)
};

/// Measured actuator displacement y_k = C z_k [mm].
double MeasuredDisplacementMm(const LinearRig& rig, const LinearRigState& s);
/// Measured damper force f_k [kN] (Eq. 34) at sample k: from the state at t_k, the actuator
/// motion x = C z_k, x' = C A z_k, and the current current_A [A] at k. 0 without a damper.
double MeasuredForceKn(const LinearRig& rig, const LinearRigState& s, double current_A);
/// Effective damper current i_c(t_k) [A] of the state (the commanded one of the last step
/// without current dynamics).
double EffectiveCurrentA(const LinearRig& rig, const LinearRigState& s);
/// MeasuredForceKn at the state's effective current.
double MeasuredForceKn(const LinearRig& rig, const LinearRigState& s);

/// Advances a LinearRigState by one step. Holds a copy of the rig and the ODE solver's workspace,
/// created once; Step() allocates nothing and depends only on (state, u, i), never on earlier
/// calls. Non-copyable, non-movable (the solver keeps a pointer to it).
class LinearRigStepper {
 public:
  explicit LinearRigStepper(const LinearRig& rig);
  LinearRigStepper(const LinearRigStepper&) = delete;
  LinearRigStepper& operator=(const LinearRigStepper&) = delete;

  /// State at k -> state at k+1, with u_mm [mm] and the commanded current current_A [A] held
  /// over [t_k, t_{k+1}) (the damper sees it through the current dynamics if they are on).
  void Step(LinearRigState* s, double u_mm, double current_A);
  const LinearRig& rig() const { return rig_; }

 private:
  static int Rhs(double t, const double* w, double* wdot, void* self);

  LinearRig rig_;
  double u_mm_ = 0.0;            // command of the step being integrated
  MrDamperCoefficients coef_{};  // damper coefficients at its current (if constant)
  CurrentDriverState current_{}; // driver state at the start of the step (after Hold)
  bool constant_current_ = true; // i_c constant over the step: coef_ holds
  OdeStepper ode_;
};

}  // namespace rths::models
