#pragma once
/// @file The CR integrator of Chen & Ricles (2008, "Development of direct integration algorithms
/// for structural dynamics using discrete control theory", J. Eng. Mech. 134(8):676-683) for a
/// NonlinearBuilding, with n sub-steps h = dt / n (docs/structures.md, "Integrators").
///
/// Explicit in displacement and velocity, with alpha1 = alpha2 = 4 (4M + 2hC + h^2 K0)^-1 M:
///
///     M a_j = -M iota a_g,j - s f - C v_j - R(x_j)              (equilibrium at j)
///     v_{j+1} = v_j + h alpha1 a_j
///     x_{j+1} = x_j + h v_j + h^2 alpha2 a_j
///
/// Unconditionally stable for linear and softening structures; second-order accurate; for a
/// linear structure its spectral radius is the trapezoidal rule's. Where f enters: f_k, measured
/// at the command x_k, in the equilibrium at t_k that gives a_k (the paper's f_{k+1} at x_{k+1},
/// one step on). With sub-steps f_k is held over [t_k, t_k+1) and a_g interpolated linearly
/// between a_g,k and a_g,k+1.
#include "models/integrator_state.h"
#include "models/nonlinear_building.h"

namespace rths::models {

struct ChenRicles {
  Eigen::MatrixXd m_inv;        ///< M^-1
  Eigen::MatrixXd h_alpha;      ///< h alpha1 [s]
  Eigen::MatrixXd h2_alpha;     ///< h^2 alpha2 [s^2]
  Eigen::VectorXd m_iota;       ///< M iota [kN s^2/mm]
  int substeps = 1;
  double dt_s = 0.0;

  /// Throws rths::Error for dt_s <= 0 or substeps outside [1, 1000].
  static ChenRicles Make(const NonlinearBuilding& b, double dt_s, int substeps = 1);
};

/// One RTHS step k -> k + 1 from (x_k, v_k) in s, a_g,k, a_g,k+1 [mm/s^2], f_k [kN]; leaves
/// x_{k+1}, v_{k+1} and a_k (s->a). Commits the springs at every x_j. No allocation.
void Advance(const ChenRicles& m, const NonlinearBuilding& b, IntegratorState* s, double ground_mm_s2,
             double ground_next_mm_s2, double force_kN);

}  // namespace rths::models
