#pragma once
/// @file Hysteretic story springs of a shear building (docs/structures.md, "Nonlinear stories"):
/// the restoring force F [kN] of one story as a function of its drift u [mm] (floor above minus
/// floor below) and of a committed history state.
///
/// Every kind writes F = r k u + (1 - r) k z, k the initial stiffness [kN/mm], r the post-yield
/// stiffness ratio and z [mm] a hysteretic displacement:
///  - linear:   r = 1 (F = k u; z unused).
///  - bouc_wen: r = alpha; z follows the Bouc-Wen law (Wen 1976, with A = 1 and z in mm, so that
///    z saturates at the yield displacement x_y when beta + gamma = 1), with the strength and
///    stiffness degradation of Baber & Noori (1985, J. Eng. Mech. 111(8), Eqs. 3-6):
///        dz/du = (A - nu(e) (beta sgn(du z) + gamma) |z / x_y|^n) / eta(e),
///        nu = 1 + delta_nu e,  eta = 1 + delta_eta e,  e = E_h / (k x_y^2),
///    E_h the hysteretic energy below. Baber & Noori drive nu and eta by the energy absorbed,
///    (1 - alpha) k \int z du per unit mass; we use the dissipated part E_h, made dimensionless by
///    k x_y^2 (delta_nu = delta_eta = 0: no degradation). For n = 1, beta = gamma = 0.5, virgin
///    loading u > 0 gives z = x_y (1 - exp(-u / x_y)).
///  - bilinear: kinematic hardening as a linear spring b k in parallel with an elastic-perfectly
///    plastic one of stiffness (1 - b) k yielding at (1 - b) F_y: r = b, z the elastic
///    deformation of the plastic one, |z| <= u_y = F_y / k (return mapping, exact).
///
/// Hysteretic energy E_h [kN mm]: the work dissipated, (1 - r) k \int z (du - dz) (the plastic
/// work of the hysteretic part; for a closed cycle the loop area \oint F du). Without stiffness
/// degradation (delta_eta = 0) it never decreases when beta >= |gamma|; with it, an unloading
/// branch (slope 1/eta < 1) gives back (1 - r) k z (du - dz) < 0, as the softened spring stores
/// more than (1 - r) k z^2 / 2.
///
/// Bouc-Wen over a drift increment du = u - u_c (u_c the committed drift): (z, E_h) integrated in u
/// by classical RK4 with m = ceil(|du| / (x_y / kBoucWenStepsPerYield)) equal sub-steps (at least
/// 1, at most kBoucWenMaxSubsteps): a deterministic function of (committed state, u). Error
/// against the closed form above (tests/models/nonlinear_structure_test.cpp): 5e-10 x_y in z and 3e-9
/// of E_h for one increment of 3 x_y (120 sub-steps); 2e-12 mm after 600 increments of x_y/200
/// (one sub-step each, the size of a 2 kHz step's drift). The tangent returned is the end-point slope
/// dF/du = k (r + (1 - r) dz/du), not the derivative of the RK4 map; the two differ by O(|du|/x_y).
#include <array>

#include "core/names.h"

namespace rths::models {

/// Hysteretic law of one story (SpringParams::kind).
enum class SpringKind { kLinear, kBoucWen, kBilinear };
inline constexpr std::array<Named<SpringKind>, 3> kSpringKindNames = {
    {{SpringKind::kLinear, "linear"}, {SpringKind::kBoucWen, "bouc_wen"}, {SpringKind::kBilinear, "bilinear"}}};

/// RK4 sub-steps per yield displacement of drift increment (Bouc-Wen).
inline constexpr double kBoucWenStepsPerYield = 40.0;
/// Upper bound on RK4 sub-steps per evaluation (an increment beyond 25 x_y loses accuracy).
inline constexpr int kBoucWenMaxSubsteps = 1000;

/// Immutable parameters of one story spring. Fields a kind does not use are ignored.
struct SpringParams {
  SpringKind kind = SpringKind::kLinear;
  double k_kN_per_mm = 1.0;  ///< initial stiffness, all kinds, (0, 1e9]
  // bouc_wen:
  double alpha = 0.1;        ///< post-yield stiffness ratio [0, 1)
  double x_y_mm = 1.0;       ///< yield displacement (0, 1e6]
  double n = 1.0;            ///< exponent [1, 20]
  double beta = 0.5;         ///< [0, 10], beta >= |gamma|, beta + gamma > 0
  double gamma = 0.5;        ///< [-10, 10]
  double delta_nu = 0.0;     ///< strength degradation per unit e (Baber & Noori) [0, 10]
  double delta_eta = 0.0;    ///< stiffness degradation per unit e (Baber & Noori) [0, 10]
  // bilinear:
  double b = 0.05;           ///< post-yield stiffness ratio [0, 1)
  double f_y_kN = 1.0;       ///< yield force (0, 1e9]

  /// Throws rths::Error(field, "must be in ... (got ...)") for the first field out of its range
  /// (only the fields of `kind`); the caller prefixes the file and key.
  void Validate() const;
  /// Yield displacement [mm]: x_y (bouc_wen), F_y / k (bilinear), 0 (linear).
  double YieldDisplacement() const;
  /// Post-yield ratio r of F = r k u + (1 - r) k z: 1 (linear), alpha, b.
  double PostYieldRatio() const;
  bool operator==(const SpringParams&) const = default;
};

/// Committed (or trial) state of one spring.
struct SpringState {
  double u_mm = 0.0;          ///< drift [mm]
  double z_mm = 0.0;          ///< hysteretic displacement [mm] (0 for linear)
  double energy_kN_mm = 0.0;  ///< dissipated hysteretic energy E_h [kN mm]
};

/// A trial evaluation: what committing would store, and the force and tangent at it.
struct SpringTrial {
  double force_kN = 0.0;            ///< F at the trial drift [kN]
  double tangent_kN_per_mm = 0.0;   ///< dF/du at the trial drift [kN/mm]
  SpringState state;                ///< the state at the trial drift (commit: assign it)
};

/// Force and tangent at drift u_mm [mm], reached along a straight path from `committed`. Pure:
/// the same inputs give the same bits; allocates nothing. Commit by storing the trial's state.
SpringTrial EvaluateSpring(const SpringParams& p, const SpringState& committed, double u_mm);

/// dz/du [-] of a Bouc-Wen spring at (z [mm], E_h [kN mm]) moving in the direction sgn_du (+1/-1).
double BoucWenSlope(const SpringParams& p, double z_mm, double energy_kN_mm, double sgn_du);

}  // namespace rths::models
