#pragma once
/// @file The physics-based servohydraulic actuator (docs/models.md section 5; the structure of the
/// paper's Fig. 2 after Dyke et al. 1995) and the rig it forms with a specimen. SI inside
/// (m, m/s, Pa, m^3/s, N, kg); the rig's interface is in paper units (u, y in mm, force in kN,
/// current in A) and converts at the boundary (docs/units.md).
///
/// Actuator, five states s = [x, x', p_L, x_v, x_v']:
///
///     e_in  = u - x                                   inner-loop error [m]        (Fig. 2)
///     i_v   = sat(+/-1, K_p e_in)                     servovalve command [-] (Fig. 2's i_c)
///     x_v'' = w_v^2 (i_v - x_v) - 2 zeta_v w_v x_v'   spool (normalised: x_v = 1 is full opening)
///     Q     = K_q x_v sqrt((P_s - sgn(x_v) p_L) / P_s) - C_tot p_L     load flow [m^3/s]
///     (V_t / 4 beta_e) p_L' = Q - A x'                oil column (compressibility)
///     m x'' = A p_L - F_load - c_p x'                 piston
///
/// The square root's argument is clamped at 0: when the load pressure opposes the open side by
/// more than the supply pressure (sgn(x_v) p_L > P_s), the valve passes no flow (rather than an
/// imaginary one); leakage still acts. In normal operation |p_L| stays below P_s (the load force
/// is below A P_s = 561 kN) and the clamp never engages. sgn(0) = 0.
///
/// F_load is the specimen's force on the piston [N], positive when it resists positive x:
/// the MR damper (Eqs. 32-39, lib/models/mr_damper.h, in mm and kN: F_load = 1e3 F(1e3 x,
/// 1e3 x', i_c)), or a linear spring-dashpot F_load = k x + c x' (tests, the equivalent damper
/// of docs/models.md section 5), or nothing.
///
/// Limits it reproduces (docs/models.md section 5): the velocity limit K_q / A (full spool, no load),
/// valve saturation for |u - x| > 1 / K_p, and the flow factor sqrt(1 - p_L / P_s) (0.81 at
/// 190 kN), a force-dependent gain loss absent from the linear models (Eqs. 28-30).
///
/// Small-signal model at rest (x_v = p_L = 0; sat and sqrt linearised: i_v = K_p e_in, Q = K_q x_v
/// - C_tot p_L) with a spring-dashpot load (k, c):
///
///     G_yu(s) = K_p K_q A V(s) / (Z(s) + K_p K_q A V(s)),   V(s) = w_v^2 / (s^2 + 2 zeta_v w_v s + w_v^2),
///     Z(s) = (m s^2 + (c + c_p) s + k)(V_t / (4 beta_e) s + C_tot) + A^2 s,
///
/// which the parameters were fitted to match with Eqs. 28 and 29 (docs/plant.md gives the match).
#include <complex>

#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/ode.h"

namespace rths::models {

/// The physics-based servohydraulic actuator (docs/models.md section 5). SI units inside, as named.
struct PhysicalActuatorConfig {
  double area_m2 = 0.0271;             ///< piston area A, (0, 1]
  double supply_pressure_Pa = 20.7e6;  ///< P_s, (0, 1e9]
  double volume_m3 = 9.26e-3;          ///< total oil volume V_t, (0, 1]
  double piston_mass_kg = 150.0;       ///< moving mass m, (0, 1e5]
  double piston_damping_N_s_m = 0.0;   ///< c_p, [0, 1e9]
  double valve_hz = 70.24;             ///< servovalve natural frequency w_v / 2 pi [Hz], (0, 1e4]
  double valve_zeta = 0.583;           ///< servovalve damping zeta_v, (0, 10]
  double kq_m3_s = 1.09e-2;            ///< flow gain K_q at full spool, (0, 10]
  double kp_per_m = 331.4;             ///< inner-loop gain K_p [1/m] (K_p K_q / A = 133.3 1/s), (0, 1e6]
  double beta_Pa = 1.172e9;            ///< effective bulk modulus beta_e, (0, 1e12]
  double leakage_m3_s_Pa = 2.693e-11;  ///< total leakage coefficient C_tot, [0, 1e-6]
  bool operator==(const PhysicalActuatorConfig&) const = default;
};

/// The actuator's parameters, SI (docs/models.md section 5; models::PhysicalActuatorConfig).
struct PhysicalActuator {
  double area_m2 = 0.0;               ///< piston area A [m^2]
  double supply_pressure_Pa = 0.0;    ///< P_s [Pa]
  double volume_m3 = 0.0;             ///< total oil volume V_t [m^3]
  double piston_mass_kg = 0.0;        ///< moving mass m [kg]
  double piston_damping_N_s_m = 0.0;  ///< c_p [N s/m]
  double valve_w_rad_s = 0.0;         ///< servovalve natural frequency w_v [rad/s]
  double valve_zeta = 0.0;            ///< servovalve damping zeta_v [-]
  double kq_m3_s = 0.0;               ///< flow gain K_q at full spool [m^3/s]
  double kp_per_m = 0.0;              ///< inner-loop proportional gain K_p [1/m]
  double beta_Pa = 0.0;               ///< effective bulk modulus beta_e [Pa]
  double leakage_m3_s_Pa = 0.0;       ///< total leakage coefficient C_tot [m^3/(s Pa)]

  /// Converts (valve_hz -> rad/s) and validates; throws rths::Error naming the bad field.
  static PhysicalActuator Make(const models::PhysicalActuatorConfig& c);
  /// K_q / A [m/s]: the piston speed at full spool with no load (0.40 m/s by default).
  double VelocityLimitM_s() const { return kq_m3_s / area_m2; }
  /// 1 / K_p [m]: the inner-loop error beyond which the valve saturates (3.0 mm by default).
  double SaturationErrorM() const { return 1.0 / kp_per_m; }
  /// K_p K_q / A [1/s]: the inner loop's gain (133 1/s by default).
  double LoopGainPerS() const { return kp_per_m * kq_m3_s / area_m2; }
  /// A P_s [N]: the largest force the piston can hold (561 kN by default).
  double ForceCapacityN() const { return area_m2 * supply_pressure_Pa; }
  /// 4 beta_e A^2 / V_t [N/m]: the oil column's stiffness.
  double OilStiffnessN_m() const { return 4.0 * beta_Pa * area_m2 * area_m2 / volume_m3; }
};

/// The actuator's state, SI.
struct ActuatorState {
  double x_m = 0.0;             ///< piston displacement x [m] (the LVDT reads it)
  double v_m_s = 0.0;           ///< piston velocity x' [m/s]
  double pL_Pa = 0.0;           ///< load pressure p_L [Pa]
  double xv = 0.0;              ///< spool position x_v [-] (1 = full opening)
  double xv_rate_per_s = 0.0;   ///< spool velocity x_v' [1/s]
};

/// Servovalve command i_v = sat(+/-1, K_p (u - x)) [-].
double ValveCommand(const PhysicalActuator& a, double u_m, double x_m);
/// Flow factor sqrt(max(0, (P_s - sgn(x_v) p_L) / P_s)) [-] (1 at no load; 0.81 at p_L = 190 kN / A
/// against the flow).
double FlowFactor(const PhysicalActuator& a, double xv, double pL_Pa);
/// Load flow Q = K_q x_v FlowFactor - C_tot p_L [m^3/s].
double LoadFlowM3_s(const PhysicalActuator& a, double xv, double pL_Pa);
/// Time derivatives of the actuator state for the command u_m [m] and the load force load_N [N]
/// (positive resisting positive x). Units: [m/s, m/s^2, Pa/s, 1/s, 1/s^2].
ActuatorState ActuatorRates(const PhysicalActuator& a, const ActuatorState& s, double u_m,
                            double load_N);

/// A linear spring-dashpot specimen F = k x + c x' [N].
struct SpringDashpot {
  double k_N_m = 0.0;    ///< stiffness [N/m], >= 0
  double c_N_s_m = 0.0;  ///< damping [N s/m], >= 0
};
/// The MR damper's equivalent spring-dashpot at the identification input (BLWN 0-50 Hz,
/// 0.254 mm RMS; docs/models.md section 5): 0.0 A and 2.5 A.
inline constexpr SpringDashpot kEquivalentDamper0A{1.10e7, 2.58e5};
inline constexpr SpringDashpot kEquivalentDamper2p5A{1.31e8, 1.91e5};

/// Small-signal frequency response x/u [m/m = mm/mm] of the actuator at rest under a
/// spring-dashpot load, in closed form (the @file's G_yu).
std::complex<double> SmallSignalResponse(const PhysicalActuator& a, const SpringDashpot& load,
                                         double f_hz);

/// What the piston drives.
enum class RigLoad {
  kNone,           ///< no specimen: F_load = 0
  kMrDamper,       ///< the MR damper, Eqs. 32-39 at the effective current
  kSpringDashpot,  ///< a linear spring-dashpot (tests, the equivalent damper)
};

/// How a step is integrated.
enum class RigIntegrator {
  kCvode,  ///< OdeStepper's adaptive, error-controlled integrator (ARKODE Dormand-Prince 5(4);
           ///< the name is historical) over [t_k, t_{k+1}) at rtol (default)
  kRk4,    ///< classical Runge-Kutta, rk4_substeps fixed steps per dt (for comparison)
};

/// Immutable description of the physical rig: actuator, specimen, current dynamics, step.
struct PhysicalRig {
  PhysicalActuator actuator;
  RigLoad load = RigLoad::kMrDamper;
  MrDamperParams damper;          ///< kMrDamper: Table 3
  SpringDashpot spring;           ///< kSpringDashpot
  bool current_dynamics = true;   ///< Eq. 40 + 75 Hz low-pass; false: i_c = commanded current
  CurrentDriver driver;           ///< used if current_dynamics
  double dt_s = 0.0;              ///< lockstep step [s]
  double rtol = 1e-8;             ///< the integrator's relative tolerance, (0, 1e-2]
  RigIntegrator integrator = RigIntegrator::kCvode;
  int rk4_substeps = 4;           ///< kRk4: fixed steps per dt, [1, 1000]

  /// Validates everything; throws rths::Error naming the bad value.
  static PhysicalRig Make(const models::PhysicalActuatorConfig& actuator, double dt_s,
                          RigLoad load, bool current_dynamics,
                          const MrDamperParams& damper = MrDamperParams::Table3(),
                          const SpringDashpot& spring = {}, double rtol = 1e-8,
                          const CurrentDriverParams& driver = {});
};

/// Per-step state at sample k.
struct PhysicalRigState {
  ActuatorState actuator;        ///< SI
  MrDamperState damper;          ///< y_d, z_bw [mm] (kMrDamper)
  CurrentDriverState current;    ///< held command and filter deviation (steady at 0 A at rest)
};

/// Measured displacement y_k = 1e3 x(t_k) [mm] (LVDT).
double MeasuredDisplacementMm(const PhysicalRig& rig, const PhysicalRigState& s);
/// Effective damper current i_c(t_k) [A] (the commanded one without current dynamics).
double EffectiveCurrentA(const PhysicalRig& rig, const PhysicalRigState& s);
/// Measured force f_k [kN] (load cell): the specimen's force F_load(t_k) / 1e3 at the state's
/// effective current; 0 without a specimen.
double MeasuredForceKn(const PhysicalRig& rig, const PhysicalRigState& s);

/// Advances a PhysicalRigState by one step. Holds a copy of the rig and its integrator workspace,
/// created once; Step() allocates nothing and depends only on (state, u, i). Non-copyable,
/// non-movable (the integrator keeps a pointer to it).
///
/// ODE state w = [x, x', p_L, x_v, x_v'] (SI) plus [y_d, z_bw] (mm) with the MR damper; the
/// effective current i_c(t) inside the step is CurrentDriver's closed form (not an ODE state).
class PhysicalRigStepper {
 public:
  explicit PhysicalRigStepper(const PhysicalRig& rig);
  PhysicalRigStepper(const PhysicalRigStepper&) = delete;
  PhysicalRigStepper& operator=(const PhysicalRigStepper&) = delete;

  /// State at k -> state at k+1, with u_mm [mm] and the commanded current i_cmd_A [A] held over
  /// [t_k, t_{k+1}).
  void Step(PhysicalRigState* s, double u_mm, double i_cmd_A);
  const PhysicalRig& rig() const { return rig_; }
  /// The integrator's internal steps in the last Step() (0 for kRk4).
  long last_internal_steps() const;

 private:
  static int Rhs(double t, const double* w, double* wdot, void* self);
  int size() const { return rig_.load == RigLoad::kMrDamper ? 7 : 5; }

  PhysicalRig rig_;
  double u_m_ = 0.0;                 // command of the step being integrated [m]
  CurrentDriverState current_{};     // driver state at the start of that step (after Hold)
  bool constant_current_ = true;     // i_c constant over the step: coef_ holds
  MrDamperCoefficients coef_{};      // damper coefficients at a constant current
  OdeStepper ode_;
  double k1_[7]{}, k2_[7]{}, k3_[7]{}, k4_[7]{}, tmp_[7]{};  // kRk4 workspace
};

}  // namespace rths::models
