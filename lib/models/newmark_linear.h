#pragma once
/// @file Newmark's method on a linear MDOF structure, as the maRTHS benchmark's substructures step
/// (its MATLAB Function blocks; fcn_num.m, fcn.m and fcn_newmark_beta_const.m of
/// FermandoisLab/maRTHS-bmk-RoDeAC): Newmark (1959), constant average acceleration by default
/// (gamma = 1/2, beta = 1/4: implicit, unconditionally stable, second order).
///
/// With the constants (the reference code's delta = gamma, alpha = beta)
///
///     a0 = 1/(beta dt^2)  a1 = gamma/(beta dt)  a2 = 1/(beta dt)  a3 = 1/(2 beta) - 1
///     a4 = gamma/beta - 1  a5 = dt/2 (gamma/beta - 2)  a6 = dt (1 - gamma)  a7 = gamma dt
///
/// one step from (U0, V0, A0) at t_{k-1} to t_k under the ground acceleration a_g,k and the
/// interface forces F_k (both at t_k, the step's end) is
///
///     Rbar = M (a0 U0 + a2 V0 + a3 A0) + C (a1 U0 + a4 V0 + a5 A0) - F_k - M l a_g,k
///     U1 = Kbar^-1 Rbar,  Kbar = K + a0 M + a1 C
///     A1 = a0 (U1 - U0) - a2 V0 - a3 A0,   V1 = V0 + a7 A1 + a6 A0
///
/// i.e. M U'' + C U' + K U = -M l a_g - F at t_k. F enters with a minus sign: it is the force the
/// physical substructure exerts on the numerical one's DOFs, positive with the DOF. Units: the
/// matrices' (SI for maRTHS). The state starts at rest; the per-step path allocates nothing.
#include <Eigen/Core>

namespace rths::models {

/// Immutable description: the matrices and the step's constants.
struct NewmarkLinear {
  Eigen::MatrixXd M, C;
  Eigen::MatrixXd Kbar_inv;  ///< (K + a0 M + a1 C)^-1
  Eigen::VectorXd Ml;        ///< M l (the ground load per unit a_g)
  double dt_s = 0.0;
  double a0 = 0, a1 = 0, a2 = 0, a3 = 0, a4 = 0, a5 = 0, a6 = 0, a7 = 0;
};

/// Builds the step for M, C, K (n x n) and the ground influence l (n) at step dt_s. Throws
/// rths::Error if sizes differ, dt_s is not > 0, gamma < 1/2 or beta not > 0, or Kbar is singular.
NewmarkLinear MakeNewmarkLinear(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                const Eigen::MatrixXd& K, const Eigen::VectorXd& l, double dt_s,
                                double gamma = 0.5, double beta = 0.25);

/// Per-step state: U, V, A at the last step's end, the interface forces F (set by the caller
/// before each step; zero elsewhere), and work space.
struct NewmarkLinearState {
  Eigen::VectorXd U, V, A;
  Eigen::VectorXd F;
  Eigen::VectorXd work_m, work_c, rbar;
};

/// At rest, sized for `m`. Allocates once.
NewmarkLinearState NewmarkLinearAtRest(const NewmarkLinear& m);

/// One step to t_k under a_g,k (the unit of l a_g: the matrices' length per s^2) and state->F.
/// Allocates nothing.
void NewmarkLinearStep(const NewmarkLinear& m, NewmarkLinearState* state, double ag);

}  // namespace rths::models
