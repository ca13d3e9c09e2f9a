#pragma once
/// @file The same-sample load coupling y_k = Post(x_k, f_k) of the rig mode and of the
/// diagnosis's block generator: a scalar fixed point f = Phi(f), Phi(f) the force at the end of
/// the step when the coupling sees f (each evaluation re-integrates the step from saved state).
#include <cmath>

namespace rths::models {

/// The fixed point found by SolveCoupledForce.
struct CoupledForce {
  double f_kN;      ///< the accepted force [kN] (the last evaluation was at it)
  bool converged;   ///< false: no root to the tolerance, the closest trial was taken
};

/// Root of h(f) = Phi(f) - f, h = eval(f). For c > 0, Phi does not increase with f (more force,
/// less displacement, less force), so h decreases strictly and f and Phi(f) bracket the root: the
/// Illinois variant of regula falsi then converges. Without a bracket (c < 0) it takes secant
/// steps. Tolerance: y is off by c h, so |h| <= 1e-9 mm / |c| (or 1e-8 relative). Starts at
/// f_start (e.g. the force extrapolated from the last two steps); at most max_iterations steps
/// after the first two evaluations. On return, eval's last call was at the returned force, so
/// whatever state eval leaves behind belongs to it. eval: double(double f_kN) -> h [kN].
template <typename Eval>
CoupledForce SolveCoupledForce(Eval&& eval, double f_start, double compliance_mm_per_kN, int max_iterations) {
  const double c = std::abs(compliance_mm_per_kN);
  const auto tol = [c](double f) { return std::max(1e-8 * (1.0 + std::abs(f)), c > 0.0 ? 1e-9 / c : 0.0); };
  double fa = f_start;
  double ha = eval(fa);
  double fb = fa + ha;
  double hb = ha == 0.0 ? 0.0 : eval(fb);
  if (ha == 0.0) fb = fa;
  double f_best = fb, h_best = hb;
  int it = 0;
  while (std::abs(hb) > tol(fb) && std::abs(fb - fa) > 1e-12 * (1.0 + std::abs(fb)) && it < max_iterations) {
    const bool bracket = (ha < 0.0) != (hb < 0.0);
    const double fc = hb != ha ? fb - hb * (fb - fa) / (hb - ha) : 0.5 * (fa + fb);
    const double hc = eval(fc);
    if (!bracket || (hc < 0.0) != (hb < 0.0)) {
      fa = fb;
      ha = hb;
    } else {
      ha *= 0.5;  // Illinois: the stale end's value halved
    }
    fb = fc;
    hb = hc;
    if (std::abs(hb) < std::abs(h_best)) f_best = fb, h_best = hb;
    ++it;
  }
  if (!std::isfinite(hb)) return {fb, false};
  if (std::abs(hb) > 1e-6 * (1.0 + std::abs(fb))) {
    // No root to the tolerance (coulomb_friction's steep sign near zero velocity makes Phi
    // non-monotone: a sticking seal): the closest trial.
    if (fb != f_best) eval(f_best);
    return {f_best, false};
  }
  return {fb, true};
}

}  // namespace rths::models
