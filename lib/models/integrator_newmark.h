#pragma once
/// @file Implicit Newmark, average acceleration (beta = 1/4, gamma = 1/2; Newmark 1959, J. Eng.
/// Mech. Div. 85(3)), with a fixed number of Newton iterations per step (a real-time budget, not a
/// tolerance) for a NonlinearBuilding (docs/structures.md, "Integrators").
///
///     x_{k+1} = x_k + dt v_k + dt^2/4 (a_k + a_{k+1}),   v_{k+1} = v_k + dt/2 (a_k + a_{k+1}),
///     r(x) = -M iota a_g,k+1 - s f_k - M a_{k+1}(x) - C v_{k+1}(x) - R(x) = 0,
///
/// solved by N Newton iterations from x^0 = x_k + dt v_k + dt^2/2 a_k with the Jacobian
/// 4M/dt^2 + 2C/dt + K_t(x^i), K_t the springs' end-point tangents (story_spring.h). After the N
/// iterations r is evaluated once more at the final x: |r|_2 [kN] is what the step leaves
/// (IntegratorState::residual_kN). Unconditionally stable for linear structures, second order.
/// Where f enters: f_{k+1} is not measured before x_{k+1} is commanded, so f_k (measured at x_k) is
/// held in the equilibrium at k+1 -- the experimental force one sample late, a first-order
/// coupling error (exact with no specimen).
#include "models/integrator_state.h"
#include "models/nonlinear_building.h"

namespace rths::models {

struct NewmarkImplicit {
  double dt_s = 0.0;
  int iterations = 1;       ///< N >= 1
  Eigen::MatrixXd m_inv;    ///< M^-1 (the start)
  Eigen::MatrixXd j_const;  ///< 4M/dt^2 + 2C/dt
  Eigen::VectorXd m_iota;   ///< M iota

  /// Throws rths::Error("newton_iterations", ...) outside [1, 100], or for dt_s <= 0.
  static NewmarkImplicit Make(const NonlinearBuilding& b, double dt_s, int newton_iterations);
};

/// Step k -> k + 1: from x_k, v_k, a_k (at k = 0 a_0 from the equilibrium at rest), a_g,k and
/// a_g,k+1 [mm/s^2], f_k [kN]. Commits the springs at the final x_{k+1}. No allocation.
void Advance(const NewmarkImplicit& m, const NonlinearBuilding& b, IntegratorState* s,
             double ground_mm_s2, double ground_next_mm_s2, double force_kN);

}  // namespace rths::models
