#include "control/dare.h"

#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "control/lti.h"
#include "core/error.h"

namespace rths::control {

DareSolution SolveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                       const Eigen::MatrixXd& R, const char* what) {
  const Eigen::Index n = A.rows(), m = B.cols();
  if (A.cols() != n || B.rows() != n || Q.rows() != n || Q.cols() != n || R.rows() != m || R.cols() != m ||
      n == 0 || m == 0) {
    throw Error(what, fmt::format("DARE dimensions disagree: A {}x{}, B {}x{}, Q {}x{}, R {}x{}", A.rows(),
                                  A.cols(), B.rows(), B.cols(), Q.rows(), Q.cols(), R.rows(), R.cols()));
  }
  const Eigen::LLT<Eigen::MatrixXd> r_chol(R);
  if (r_chol.info() != Eigen::Success) throw Error(what, "DARE: R is not positive definite");

  // Balance: x = D x~, A~ = D^-1 A D, B~ = D^-1 B, Q~ = D Q D; then X = D^-1 X~ D^-1, K = K~ D^-1.
  const Eigen::VectorXd d = BalancingScale(A);
  const Eigen::MatrixXd a = d.cwiseInverse().asDiagonal() * A * d.asDiagonal();
  const Eigen::MatrixXd b = d.cwiseInverse().asDiagonal() * B;
  const Eigen::MatrixXd q = d.asDiagonal() * Q * d.asDiagonal();
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);

  Eigen::MatrixXd ak = a, gk = b * r_chol.solve(b.transpose()), hk = 0.5 * (q + q.transpose());
  gk = 0.5 * (gk + gk.transpose());
  int it = 0;
  bool converged = false;
  for (; it < 100 && !converged; ++it) {
    const Eigen::PartialPivLU<Eigen::MatrixXd> w(I + gk * hk);
    const Eigen::MatrixXd wa = w.solve(ak);   // W^-1 A_k
    const Eigen::MatrixXd wg = w.solve(gk);   // W^-1 G_k
    Eigen::MatrixXd h_next = hk + ak.transpose() * hk * wa;
    Eigen::MatrixXd g_next = gk + ak * wg * ak.transpose();
    h_next = 0.5 * (h_next + h_next.transpose());
    g_next = 0.5 * (g_next + g_next.transpose());
    ak = ak * wa;
    // Norms, not entries: entries near 1e300 overflow every later product.
    if (!std::isfinite(h_next.norm()) || !std::isfinite(g_next.norm()) || !std::isfinite(ak.norm())) {
      throw Error(what, fmt::format("DARE has no stabilising solution: the doubling iteration diverged after "
                                    "{} steps (an unstable mode that the input cannot reach?)",
                                    it + 1));
    }
    converged = (h_next - hk).norm() <= 1e-14 * h_next.norm();
    hk = std::move(h_next);
    gk = std::move(g_next);
  }
  if (!converged) {
    throw Error(what, fmt::format("DARE: the doubling iteration did not converge in {} steps", it));
  }

  const Eigen::MatrixXd& x = hk;
  const Eigen::MatrixXd s = R + b.transpose() * x * b;
  const Eigen::MatrixXd k = s.ldlt().solve(b.transpose() * x * a);
  const Eigen::MatrixXd res = a.transpose() * x * a - x - a.transpose() * x * b * k + q;
  DareSolution sol;
  sol.iterations = it;
  sol.residual = res.norm() / std::max({x.norm(), q.norm(), 1e-300});
  sol.X = d.cwiseInverse().asDiagonal() * x * d.cwiseInverse().asDiagonal();
  sol.K = k * d.cwiseInverse().asDiagonal();
  sol.closed_loop = (a - b * k).eigenvalues();
  const double rho = sol.closed_loop.cwiseAbs().maxCoeff();
  if (!std::isfinite(sol.residual) || !sol.K.allFinite()) {
    throw Error(what, "DARE has no stabilising solution: the doubling iteration diverged");
  }
  if (!(sol.residual < 1e-9)) {
    throw Error(what, fmt::format("DARE: the solution's residual {:.3g} is too large (ill-conditioned)", sol.residual));
  }
  if (!(rho < 1.0)) {
    throw Error(what, fmt::format("DARE has no stabilising solution: the closed loop A - B K has an eigenvalue "
                                  "of modulus {:.6g} >= 1 (an unstable mode that the weights cannot see? the doubling algorithm needs (Q, A) detectable)",
                                  rho));
  }
  return sol;
}

}  // namespace rths::control
