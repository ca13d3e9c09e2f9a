#pragma once
/// @file The damped step of Levenberg-Marquardt shared by the damper fits (damper_fit.h,
/// spencer_fit.h). With the Gauss-Newton matrix H = J^T J and gradient g = J^T r at theta:
///
///     (H + mu D) d = -g,   D = diag(max(H_ii, 1e-12))        (Marquardt's scaling)
///     trial = clamp(theta + d)                                (projected on the parameter box)
///
/// accepted if its cost is finite and below the current one (then mu <- max(mu / 3, 1e-9)),
/// else mu <- 4 mu and again, until mu reaches 1e12.
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace rths::ident {

/// One damped step (file comment). `evaluate(trial)` returns an evaluation with a `cost` member;
/// on acceptance *theta and *ev take the trial's. Sets *converged when no step is accepted, or the
/// accepted one lowers the cost by less than rel_tol (relative) or moves theta by less than
/// step_tol. Returns true if a step was accepted.
template <typename Theta, typename Evaluation, typename Evaluate, typename Clamp>
bool DampedStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Theta* theta, Evaluation* ev, double* mu,
                Evaluate&& evaluate, Clamp&& clamp, double rel_tol, double step_tol, bool* converged) {
  while (*mu < 1e12) {
    Eigen::MatrixXd Hd = H;
    for (Eigen::Index i = 0; i < H.rows(); ++i) Hd(i, i) += *mu * std::max(H(i, i), 1e-12);
    // The step in theta's own type first: a fixed-size destination takes another solver path,
    // and the fits' results are kept to the last digit.
    const Theta step = Hd.ldlt().solve(-g);
    const Theta trial = clamp(Theta(*theta + step));
    auto e = evaluate(trial);
    if (std::isfinite(e.cost) && e.cost < ev->cost) {
      const double rel = (ev->cost - e.cost) / std::max(ev->cost, 1e-300);
      const double dstep = (trial - *theta).norm();
      *theta = trial;
      *ev = std::move(e);
      *mu = std::max(*mu / 3.0, 1e-9);
      if (rel < rel_tol || dstep < step_tol) *converged = true;
      return true;
    }
    *mu *= 4.0;
  }
  *converged = true;
  return false;
}

}  // namespace rths::ident
