#pragma once
/// @file The Spencer et al. (1997) phenomenological MR damper model, as identified for the
/// 200-kN damper of the paper (Eqs. 32-39, Table 3; docs/models.md section 6). Units: mm, kN, s, A.
///
/// States y [mm] (internal displacement) and z [mm] (Bouc-Wen evolutionary variable), driven by
/// the damper displacement x [mm] and velocity x' [mm/s]:
///
///     c1 y' = alpha z + k0 (x - y) + c0 (x' - y')                                    (Eq. 32)
///  => y'    = (alpha z + k0 (x - y) + c0 x') / (c0 + c1)
///     z'    = -gamma |x' - y'| z |z|^(n-1) - beta (x' - y') |z|^n + A (x' - y')     (Eq. 33)
///     F     = alpha z + c0 (x' - y') + k0 (x - y) + k1 (x - x0)                      (Eq. 34)
///
/// with alpha, c0, c1, beta, gamma depending on the current i [A] as p = p_b + (p_a - p_b)
/// exp(-p_c i) (Eqs. 35-39). Current dynamics (Eq. 40) are not part of this file.
#include <limits>

#include "models/ode.h"

namespace rths::models {

/// Table 3 of the paper (defaults). a: fitted at 0.0 A, b: at 2.5 A, c: exponential rate.
struct MrDamperParams {
  double alpha_a = 0.11, alpha_b = 0.55, alpha_c = 1.0;     ///< [kN/mm], [kN/mm], [1/A]
  double c0_a = 0.080, c0_b = 0.32, c0_c = 1.5;             ///< [kN s/mm], [kN s/mm], [1/A]
  double c1_a = 3.0, c1_b = 15.0, c1_c = 2.0;               ///< [kN s/mm], [kN s/mm], [1/A]
  double beta_a = 0.050, beta_b = 0.0020, beta_c = 5.2;     ///< [1/mm^2], [1/mm^2], [1/A]
  double gamma_a = 0.050, gamma_b = 0.0020, gamma_c = 5.2;  ///< [1/mm^2], [1/mm^2], [1/A]
  double A = 300.0;                                         ///< Bouc-Wen A [-]
  double n = 2.0;                                           ///< Bouc-Wen exponent [-], >= 1
  double k0 = 0.0;                                          ///< [kN/mm]
  double k1 = 0.0;                                          ///< accumulator stiffness [kN/mm]
  double x0 = 0.0;                                          ///< accumulator offset [mm]

  /// The paper's identified 200-kN damper (same as the defaults).
  static MrDamperParams Table3() { return {}; }
  /// Throws rths::Error naming the first invalid field (c0, c1 > 0; alpha, beta, gamma, A,
  /// k0, k1 >= 0; rates >= 0; n >= 1; all finite).
  void Validate() const;
  bool operator==(const MrDamperParams&) const = default;
};

/// One field of MrDamperParams as scenarios, model files and messages name it: its key, the
/// member, and its lower bound (Validate; -inf: only finite).
struct MrDamperField {
  const char* key;
  double MrDamperParams::*member;
  double min;
  bool strict;  ///< value > min (else >= min)
};
/// Every MrDamperParams field, in the order of the struct (the one list of the 20 keys: the
/// scenario reader and writer, Validate and the model files of rths identify walk it).
inline constexpr MrDamperField kMrDamperFields[] = {
    {"alpha_a", &MrDamperParams::alpha_a, 0, false}, {"alpha_b", &MrDamperParams::alpha_b, 0, false},
    {"alpha_c", &MrDamperParams::alpha_c, 0, false}, {"c0_a", &MrDamperParams::c0_a, 0, true},
    {"c0_b", &MrDamperParams::c0_b, 0, true},        {"c0_c", &MrDamperParams::c0_c, 0, false},
    {"c1_a", &MrDamperParams::c1_a, 0, true},        {"c1_b", &MrDamperParams::c1_b, 0, true},
    {"c1_c", &MrDamperParams::c1_c, 0, false},       {"beta_a", &MrDamperParams::beta_a, 0, false},
    {"beta_b", &MrDamperParams::beta_b, 0, false},   {"beta_c", &MrDamperParams::beta_c, 0, false},
    {"gamma_a", &MrDamperParams::gamma_a, 0, false}, {"gamma_b", &MrDamperParams::gamma_b, 0, false},
    {"gamma_c", &MrDamperParams::gamma_c, 0, false}, {"A", &MrDamperParams::A, 0, false},
    {"n", &MrDamperParams::n, 1, false},             {"k0", &MrDamperParams::k0, 0, false},
    {"k1", &MrDamperParams::k1, 0, false},
    {"x0", &MrDamperParams::x0, -std::numeric_limits<double>::infinity(), false},
};

/// The model's coefficients at one current (Eqs. 35-39); units as in MrDamperParams.
struct MrDamperCoefficients {
  double alpha, c0, c1, beta, gamma, A, n, k0, k1, x0;
};
/// Eqs. 35-39 at current_A [A] (>= 0 expected; not clipped).
MrDamperCoefficients CoefficientsAt(const MrDamperParams& p, double current_A);

/// Per-step state.
struct MrDamperState {
  double y_mm = 0.0;  ///< internal displacement y [mm]
  double z_mm = 0.0;  ///< evolutionary variable z [mm] (alpha z is in kN)
};
/// Time derivatives of the state [mm/s].
struct MrDamperRates {
  double ydot_mm_s;
  double zdot_mm_s;
};

/// Eqs. 32-33 at displacement x_mm [mm] and velocity xdot_mm_s [mm/s]. For n = 2 it uses
/// z|z| and z^2 (no pow). Allocates nothing.
MrDamperRates DamperRates(const MrDamperCoefficients& k, const MrDamperState& s, double x_mm,
                          double xdot_mm_s);
/// Eq. 34: damper force F [kN], positive when it pushes against positive x (a resisting force
/// for x' > 0), with y' from Eq. 32 at the same instant.
double DamperForceKn(const MrDamperCoefficients& k, const MrDamperState& s, double x_mm,
                     double xdot_mm_s);

/// Advances the damper over one step for a prescribed motion x(t), x'(t) at a constant current.
/// Owns its integrator workspace (OdeStepper: ARKODE's Dormand-Prince 5(4) by default, CVODE's BDF
/// on request); allocates nothing per step.
class MrDamperStepper {
 public:
  /// Prescribed motion: writes x(t) [mm] and x'(t) [mm/s] at t_s [s].
  using Motion = void (*)(double t_s, void* ctx, double* x_mm, double* xdot_mm_s);

  /// params are validated (throws rths::Error); motion_ctx must outlive the stepper; rtol is
  /// the integrator's relative tolerance, the absolute one is rtol * 0.01 mm.
  MrDamperStepper(const MrDamperParams& params, Motion motion, void* motion_ctx,
                  double rtol = 1e-8, OdeMethod method = OdeMethod::kErk);
  MrDamperStepper(const MrDamperStepper&) = delete;
  MrDamperStepper& operator=(const MrDamperStepper&) = delete;

  /// Integrates the state from t0_s to t1_s [s] with current_A [A] held constant.
  void Advance(double t0_s, double t1_s, double current_A, MrDamperState* s);
  /// Force F(t_s) [kN] (Eq. 34) for the state at t_s and the current current_A [A].
  double ForceKn(double t_s, double current_A, const MrDamperState& s) const;
  const MrDamperParams& params() const { return params_; }

 private:
  static int Rhs(double t, const double* x, double* xdot, void* self);

  MrDamperParams params_;
  Motion motion_;
  void* motion_ctx_;
  MrDamperCoefficients coef_{};  // at the current of the step being integrated
  OdeStepper ode_;
};

}  // namespace rths::models
