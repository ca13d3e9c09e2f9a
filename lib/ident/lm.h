#pragma once
/// @file The damped step of Levenberg-Marquardt shared by the damper fits (damper_fit.h,
/// spencer_fit.h). With the Gauss-Newton matrix H = J^T J and gradient g = J^T r at theta:
///
///     (H + mu D) d = -g,   D = diag(max(H_ii, 1e-12))        (Marquardt's scaling)
///     trial = clamp(theta + d, lo, hi)                        (projected on the parameter box)
///
/// accepted if its cost is finite and below the current one (then mu <- max(mu / 3, 1e-9)),
/// else mu <- 4 mu and again, until mu reaches 1e12.
///
/// Bounds (an active set): a coordinate on a bound whose gradient pushes it outward (at lo with
/// g_i > 0, at hi with g_i < 0), or whose box is a point (lo_i = hi_i: a held parameter), is taken
/// out of the system (d_i = 0) before solving. Without this the unconstrained step of a coordinate
/// the cost wants beyond its bound is cut by the clamp, the clipped step is no longer a descent
/// direction for the others, mu grows, and the fit creeps to its iteration limit (a parameter that
/// wants to be 0, e.g. beta or k0, on its floor: docs/identification.md "When a fit fails").
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace rths::ident {

/// theta clamped coordinate-wise into [lo, hi].
template <typename Theta>
Theta ClampToBox(const Theta& theta, const Theta& lo, const Theta& hi) {
  Theta out = theta;
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] = std::clamp(out[i], lo[i], hi[i]);
  return out;
}

/// One damped step (file comment) in the box [lo, hi]. `evaluate(trial)` returns an evaluation
/// with a `cost` member; on acceptance *theta and *ev take the trial's. Sets *converged when no
/// step is accepted, or the accepted one lowers the cost by less than rel_tol (relative) or moves
/// theta by less than step_tol. Returns true if a step was accepted.
template <typename Theta, typename Evaluation, typename Evaluate>
bool DampedStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Theta* theta, Evaluation* ev, double* mu,
                Evaluate&& evaluate, const Theta& lo, const Theta& hi, double rel_tol, double step_tol,
                bool* converged) {
  // The active set (file comment): those coordinates decouple, with a zero step.
  Eigen::MatrixXd Ha = H;
  Eigen::VectorXd ga = g;
  for (Eigen::Index i = 0; i < H.rows(); ++i) {
    const bool held = !(lo[i] < hi[i]);
    const bool out_lo = (*theta)[i] <= lo[i] && g[i] > 0.0, out_hi = (*theta)[i] >= hi[i] && g[i] < 0.0;
    if (!(held || out_lo || out_hi)) continue;
    Ha.row(i).setZero();
    Ha.col(i).setZero();
    Ha(i, i) = 1.0;
    ga[i] = 0.0;
  }
  while (*mu < 1e12) {
    Eigen::MatrixXd Hd = Ha;
    for (Eigen::Index i = 0; i < Ha.rows(); ++i) Hd(i, i) += *mu * std::max(Ha(i, i), 1e-12);
    // The step in theta's own type first: a fixed-size destination takes another solver path,
    // and the fits' results are kept to the last digit.
    const Theta step = Hd.ldlt().solve(-ga);
    const Theta trial = ClampToBox(Theta(*theta + step), lo, hi);
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
