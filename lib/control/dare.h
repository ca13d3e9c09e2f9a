#pragma once
/// @file Discrete algebraic Riccati equation (LQR and Kalman designs, docs/models.md section 4).
///
///   X = A^T X A - A^T X B (R + B^T X B)^-1 B^T X A + Q,   K = (R + B^T X B)^-1 B^T X A,
///
/// the stabilising solution (A - B K has every eigenvalue inside the unit circle). Solved by the
/// structure-preserving doubling algorithm (SDA; Chu, Fan, Lin & Wang 2004): with A_0 = A,
/// G_0 = B R^-1 B^T, H_0 = Q,
///   W_k = I + G_k H_k,  A_{k+1} = A_k W_k^-1 A_k,  G_{k+1} = G_k + A_k W_k^-1 G_k A_k^T,
///   H_{k+1} = H_k + A_k^T H_k W_k^-1 A_k,
/// H_k -> X quadratically (the error falls like rho(A - B K)^(2^k)). The problem is first
/// balanced by a diagonal state scaling x = D x~ (lti.h BalancingScale), which the servo models
/// need (their phase-variable states span 1 to 1e7); everything is in double precision. The
/// solution is then checked: finite, symmetric, small residual, stabilising.
#include <Eigen/Core>

namespace rths::control {

struct DareSolution {
  Eigen::MatrixXd X;            ///< stabilising solution, dim n x n, symmetric
  Eigen::MatrixXd K;            ///< gain (R + B^T X B)^-1 B^T X A, dim m x n
  Eigen::VectorXcd closed_loop; ///< eigenvalues of A - B K, dim n (all |.| < 1)
  double residual = 0.0;        ///< ||Riccati residual||_F / max(||X||_F, ||Q||_F), balanced basis
  int iterations = 0;           ///< doubling steps taken
};

/// Solves the DARE for A (n x n), B (n x m), Q (n x n, symmetric >= 0), R (m x m, symmetric > 0),
/// assuming (A, B) stabilisable and (Q, A) detectable (as the LQR and Kalman designs here are).
/// Throws rths::Error (where = `what`, e.g. "controller.lqg: LQR") if the dimensions disagree, the
/// iteration does not converge, or it finds no stabilising solution (an unstable mode that B cannot
/// reach, or that Q cannot see), saying which.
DareSolution SolveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                       const Eigen::MatrixXd& R, const char* what = "DARE");

}  // namespace rths::control
