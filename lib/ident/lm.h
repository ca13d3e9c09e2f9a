#pragma once
/// @file Levenberg-Marquardt, the one driver of the fits: Eq. 15's (fit.h) and the two damper
/// fits' (damper_fit.h, spencer_fit.h). With the Gauss-Newton matrix H = J^T J and gradient
/// g = J^T r at theta, one damped step is
///
///     (H + mu D) d = -g,   D = diag(max(H_ii, floor))        (Marquardt's scaling)
///     trial = clamp(theta + d, lo, hi)                        (projected on the parameter box)
///
/// accepted if its cost is finite and below the current one (then mu <- max(mu / down, mu_min)),
/// else mu <- up x mu and again, until mu reaches mu_max or max_tries trials were made
/// (LmDamping: the damper fits x4 / 3 with an active set, Eq. 15's fit x10 / 10 without).
///
/// Bounds (an active set, LmDamping::active_set): a coordinate on a bound whose gradient pushes it
/// outward (at lo with g_i > 0, at hi with g_i < 0), or whose box is a point (lo_i = hi_i: a held
/// parameter), is taken out of the system (d_i = 0) before solving. Without this the
/// unconstrained step of a coordinate the cost wants beyond its bound is cut by the clamp, the
/// clipped step is no longer a descent direction for the others, mu grows, and the fit creeps to
/// its iteration limit (a parameter that wants to be 0, e.g. beta or k0, on its floor:
/// docs/identification.md "When a fit fails").
///
/// LmIterate is the damper fits' whole loop: a forward-difference Jacobian (ForwardDifferenceColumn,
/// columns on threads if asked), the damped step, the convergence test.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Dense>

namespace rths::ident {

/// theta clamped coordinate-wise into [lo, hi].
template <typename Theta>
Theta ClampToBox(const Theta& theta, const Theta& lo, const Theta& hi) {
  Theta out = theta;
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] = std::clamp(out[i], lo[i], hi[i]);
  return out;
}

/// The box a fit searches theta in (natural log of the parameters' bounds, as the fit's own
/// parameterisation says), a point for a held parameter with the reason it is held.
template <typename Theta>
struct LmBox {
  Theta lo, hi;
  std::vector<std::string> held_why;  ///< per coordinate: why it is held ("" = fitted)

  /// dim coordinates, each [lo_of(i), hi_of(i)], none held.
  template <typename Lo, typename Hi>
  LmBox(int dim, Lo&& lo_of, Hi&& hi_of) : held_why(static_cast<std::size_t>(dim)) {
    lo.resize(dim);
    hi.resize(dim);
    for (int i = 0; i < dim; ++i) lo[i] = lo_of(i), hi[i] = hi_of(i);
  }
  /// Holds coordinate i at `value` (in theta's units), for `why`.
  void Hold(int i, double value, std::string why) {
    lo[i] = hi[i] = value;
    held_why[static_cast<std::size_t>(i)] = std::move(why);
  }
  bool Held(int i) const { return !held_why[static_cast<std::size_t>(i)].empty(); }
  Theta Clamp(const Theta& th) const { return ClampToBox(th, lo, hi); }
};

/// How DampedStep damps and when it gives up (file comment).
struct LmDamping {
  double up = 4.0;                 ///< mu <- up x mu after a rejected trial
  double down = 3.0;               ///< mu <- max(mu / down, mu_min) after an accepted one
  double mu_min = 1e-9;
  double mu_max = 1e12;            ///< no trial once mu has reached it
  int max_tries = std::numeric_limits<int>::max();  ///< trials per step at most
  double diag_floor = 1e-12;       ///< floor of D's entries
  bool active_set = true;          ///< take the coordinates pushed outward, and held ones, out (file comment)
  bool accept_equal = false;       ///< accept a trial whose cost equals the current one
  bool skip_nonfinite_step = false;  ///< a step d that is not finite counts as rejected, unevaluated
};

/// Eq. 15's fit's damping (fit.h): x10 either way (mu at least 1e-12), at most 40 trials a step,
/// no active set (its box lies far outside any fitted band's rates), D's floor 1e-30, an equal
/// cost accepted, a step that is not finite skipped. (The damper fits: LmDamping's defaults.)
inline LmDamping PoleFitDamping() {
  LmDamping r;
  r.up = r.down = 10.0;
  r.mu_min = 1e-12;
  r.mu_max = std::numeric_limits<double>::infinity();
  r.max_tries = 40;
  r.diag_floor = 1e-30;
  r.active_set = false;
  r.accept_equal = true;
  r.skip_nonfinite_step = true;
  return r;
}

/// What one DampedStep did.
struct LmStep {
  bool accepted = false;
  double old_cost = 0.0, new_cost = 0.0;  ///< the cost before and after (if accepted)
  double step_norm = 0.0;                 ///< |trial - theta| of the accepted trial (after the clamp)
  double solved_norm = 0.0;               ///< |d| of the accepted trial (before the clamp)
};

/// One damped step (file comment) in the box [lo, hi]. `evaluate(trial)` returns an evaluation
/// with a `cost` member; on acceptance *theta and *ev take the trial's.
template <typename Theta, typename Evaluation, typename Evaluate>
LmStep DampedStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Theta* theta, Evaluation* ev, double* mu,
                  Evaluate&& evaluate, const Theta& lo, const Theta& hi, const LmDamping& rule = {}) {
  // The active set (file comment): those coordinates decouple, with a zero step.
  Eigen::MatrixXd Ha = H;
  Eigen::VectorXd ga = g;
  for (Eigen::Index i = 0; rule.active_set && i < H.rows(); ++i) {
    const bool held = !(lo[i] < hi[i]);
    const bool out_lo = (*theta)[i] <= lo[i] && g[i] > 0.0, out_hi = (*theta)[i] >= hi[i] && g[i] < 0.0;
    if (!(held || out_lo || out_hi)) continue;
    Ha.row(i).setZero();
    Ha.col(i).setZero();
    Ha(i, i) = 1.0;
    ga[i] = 0.0;
  }
  LmStep out;
  out.old_cost = ev->cost;
  for (int tries = 0; *mu < rule.mu_max && tries < rule.max_tries; ++tries) {
    Eigen::MatrixXd Hd = Ha;
    for (Eigen::Index i = 0; i < Ha.rows(); ++i) Hd(i, i) += *mu * std::max(Ha(i, i), rule.diag_floor);
    // The step in theta's own type first: a fixed-size destination takes another solver path,
    // and the fits' results are kept to the last digit.
    const Theta step = Hd.ldlt().solve(-ga);
    if (rule.skip_nonfinite_step && !step.allFinite()) {
      *mu *= rule.up;
      continue;
    }
    const Theta trial = ClampToBox(Theta(*theta + step), lo, hi);
    auto e = evaluate(trial);
    if (std::isfinite(e.cost) && (e.cost < ev->cost || (rule.accept_equal && e.cost == ev->cost))) {
      out.accepted = true;
      out.new_cost = e.cost;
      out.step_norm = (trial - *theta).norm();
      out.solved_norm = step.norm();
      *theta = trial;
      *ev = std::move(e);
      *mu = std::max(*mu / rule.down, rule.mu_min);
      return out;
    }
    *mu *= rule.up;
  }
  return out;
}

/// A search's state: where it is, its evaluation there, its damping, how far it went.
template <typename Theta, typename Evaluation>
struct LmState {
  Theta theta;
  Evaluation ev;
  double mu = 1e-3;
  int iterations = 0;
  bool converged = false;
};

/// Column i of the forward-difference Jacobian of the residuals r at theta, into J:
/// (r(theta + h e_i) - r) / h with h = 1e-5 (-1e-5 where theta_i + h would leave the box above);
/// zero for a held coordinate (no column: DampedStep keeps it) or where the perturbed cost is not
/// finite. `perturbed(theta')` evaluates theta' as the base point does (the same substeps).
template <typename Theta, typename Evaluation, typename Box, typename Perturbed>
void ForwardDifferenceColumn(const Theta& theta, const Evaluation& base, int i, const Box& box, Perturbed&& perturbed,
                             Eigen::MatrixXd* J) {
  if (box.Held(i)) {
    J->col(i).setZero();
    return;
  }
  Theta t = theta;
  double h = 1e-5;
  if (t[i] + h > box.hi[i]) h = -h;
  t[i] += h;
  const Evaluation e = perturbed(t);
  if (std::isfinite(e.cost))
    J->col(i) = (e.r - base.r) / h;
  else
    J->col(i).setZero();
}

/// Up to `iterations` Levenberg-Marquardt iterations of the damper fits from *s, in `box`: at
/// each, `base(theta)` (the point the Jacobian is taken at; a cost that is not finite ends the
/// search, converged), the Jacobian by ForwardDifferenceColumn with `perturbed(theta', base,
/// thread)` (columns spread over `threads` threads if > 1), then DampedStep with `trial(theta')`
/// under `rule`. Converged when no step is accepted, or the accepted one lowers the cost by less
/// than rel_tol (relative to the cost before) or moves theta by less than step_tol.
/// `on_iteration` (may be empty) is called after each iteration.
template <typename Theta, typename Evaluation, typename Box, typename Base, typename Perturbed, typename Trial>
void LmIterate(LmState<Theta, Evaluation>* s, const Box& box, int iterations, Base&& base, Perturbed&& perturbed,
               Trial&& trial, double rel_tol, double step_tol, int threads = 1,
               const std::function<void()>& on_iteration = {}, const LmDamping& rule = {}) {
  const int P = static_cast<int>(s->theta.size());
  for (int it = 0; it < iterations && !s->converged; ++it) {
    const Evaluation b = base(s->theta);
    if (!std::isfinite(b.cost)) {
      s->converged = true;
      return;
    }
    Eigen::MatrixXd J(b.r.size(), P);
    auto column = [&](int i, int t) {
      ForwardDifferenceColumn(s->theta, b, i, box, [&](const Theta& th) { return perturbed(th, b, t); }, &J);
    };
    if (threads <= 1) {
      for (int i = 0; i < P; ++i) column(i, 0);
    } else {
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
          for (int i = t; i < P; i += threads) column(i, t);
        });
      for (auto& th : pool) th.join();
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * b.r;
    ++s->iterations;
    const LmStep step = DampedStep(H, g, &s->theta, &s->ev, &s->mu, trial, box.lo, box.hi, rule);
    if (!step.accepted) {
      s->converged = true;
    } else {
      const double rel = (step.old_cost - step.new_cost) / std::max(step.old_cost, 1e-300);
      if (rel < rel_tol || step.step_norm < step_tol) s->converged = true;
    }
    if (on_iteration) on_iteration();
  }
}

}  // namespace rths::ident
