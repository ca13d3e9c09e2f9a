#pragma once
/// @file Central differences (Eqs. 2-3 of the paper) for a NonlinearBuilding, with n sub-steps
/// h = dt / n per RTHS step (docs/structures.md, "Integrators").
///
/// With Khat = M/h^2 + C/(2h) and R(x) the restoring force (nonlinear_building.h):
///
///     Khat x_{j+1} = (2M/h^2) x_j - R(x_j) - (M/h^2 - C/(2h)) x_{j-1} - M iota a_g,j - s f_k,
///
/// computed as today's linear recurrence of (M, C, K0) (models::CentralDifference, the same
/// matrices and the same operations) plus the correction Khat^-1 (K0 x_j - R(x_j)), skipped when
/// every spring is linear: then the numbers are bit-identical to models::CentralDifference.
/// Where f enters: f_k, measured at x_k (the command of sample k), in the equilibrium at t_k;
/// with sub-steps it is held over [t_k, t_k+1) (zero-order hold: the next measurement does not
/// exist yet), and the ground is interpolated linearly between a_g,k and a_g,k+1 (exact for a
/// record interpolated linearly between samples). Explicit: stable for h < T_min / pi of the
/// initial stiffness (softening keeps it so); Make throws at or above the limit.
#include "models/integrator_state.h"
#include "models/nonlinear_building.h"
#include "models/structure.h"

namespace rths::models {

struct NonlinearCentralDifference {
  CentralDifference linear;  ///< the recurrence of (M, C, K0) at h
  Eigen::MatrixXd khat_inv;  ///< Khat^-1 [mm/kN]
  Eigen::MatrixXd K0;        ///< [kN/mm]
  int substeps = 1;          ///< n
  double dt_s = 0.0;         ///< RTHS step [s]
  bool all_linear = true;

  /// Throws rths::Error for dt_s <= 0, substeps outside [1, 1000], or h = dt/n at or above the
  /// stability limit (naming the highest frequency and the limit).
  static NonlinearCentralDifference Make(const NonlinearBuilding& b, double dt_s, int substeps = 1);
};

/// One RTHS step k -> k + 1: from x_k (s->x) and the previous (sub-)step, a_g,k and a_g,k+1
/// [mm/s^2], f_k [kN]. Commits the springs at each (sub-)step's x_j. No allocation.
void Advance(const NonlinearCentralDifference& m, const NonlinearBuilding& b, IntegratorState* s,
             double ground_mm_s2, double ground_next_mm_s2, double force_kN);

}  // namespace rths::models
