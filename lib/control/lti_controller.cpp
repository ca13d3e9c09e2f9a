#include "control/lti_controller.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {

std::string PoleText(std::complex<double> z, double dt_s, bool with_s) {
  std::string t = fmt::format("z = {:.6g}{:+.6g}j (|z| = {:.6g})", z.real(), z.imag(), std::abs(z));
  if (with_s && std::abs(z) > 0.0) {
    const std::complex<double> s = std::log(z) / dt_s;
    t += fmt::format(", s = {:.6g}{:+.6g}j 1/s", s.real(), s.imag());
  }
  return t;
}

LtiPart MakePart(const TfCoefficients& tf, const LtiConfig& cfg, double dt_s, const std::string& key) {
  LtiPart p;
  p.discrete.dt_s = dt_s;
  if (tf.Empty()) return p;  // 1
  p.given = true;
  p.coefficients = tf;
  const TfChecked c = CheckTf(tf, key);
  if (cfg.domain == TfDomain::kZ) {
    p.discrete = ZDomainTf(c, dt_s);
  } else {
    p.s_poles = PolynomialRoots(c.den);
    p.discrete = cfg.discretisation == Discretisation::kZoh ? ZohTf(c, dt_s) : TustinTf(c, dt_s);
  }
  for (double v : p.discrete.b) {
    if (!std::isfinite(v)) {
      throw Error(key, "the discretised numerator is not finite (coefficients too large for run.dt_s?)");
    }
  }
  p.stability = StabilityOf(p.discrete);
  if (!p.stability.Stable() && !cfg.allow_unstable) {
    std::string poles;
    for (const auto z : p.discrete.Poles()) {
      if (std::abs(z) >= 1.0 - kIntegratorTolerance) poles += "; " + PoleText(z, dt_s, cfg.domain == TfDomain::kS);
    }
    throw Error(key, fmt::format("unstable: {} pole(s) on or outside the unit circle besides one integrator ({} "
                                 "integrator(s) at z = 1){}. One integrator (a pole at s = 0, as in a PI) is "
                                 "accepted; set controller.lti.allow_unstable = true to run anything else",
                                 p.stability.unstable, p.stability.integrators, poles));
  }
  return p;
}

/// x limited to [-limit, limit] (limit 0: no limit).
double Limit(double x, double limit) { return limit > 0.0 ? std::clamp(x, -limit, limit) : x; }

}  // namespace

LtiDesign MakeLtiDesign(const LtiConfig& cfg, double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  for (auto [key, v] : {std::pair{"controller.lti.saturation_mm", cfg.saturation_mm},
                        {"controller.lti.rate_limit_mm_s", cfg.rate_limit_mm_s}}) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw Error(key, fmt::format("{}: allowed >= 0 (0: no limit)", v));
  }
  LtiDesign d;
  d.config = cfg;
  d.dt_s = dt_s;
  d.feedback = MakePart(cfg.feedback, cfg, dt_s, "controller.lti.feedback");
  d.reference = MakePart(cfg.reference, cfg, dt_s, "controller.lti.reference");
  return d;
}

Command LtiStep(const LtiDesign& d, LtiState* s, double r_mm, double y_mm) {
  const double t = FilterStep(d.reference.discrete, &s->reference, r_mm);
  const double v = FilterStep(d.feedback.discrete, &s->feedback, t - y_mm);
  const double u_fb = FilterStep(d.feedback.discrete, &s->feedback_plain, r_mm - y_mm);
  double u = v;
  if (d.config.rate_limit_mm_s > 0.0) {
    const double step = d.config.rate_limit_mm_s * d.dt_s;
    u = std::clamp(u, s->u_prev_mm - step, s->u_prev_mm + step);
  }
  u = Limit(u, d.config.saturation_mm);
  s->u_prev_mm = u;
  return {u, u - u_fb, u_fb};
}

ControllerLti LtiController::Linearize(double) const {
  const DiscreteSs c = design_.feedback.discrete.ToStateSpace();
  const DiscreteSs t = design_.reference.discrete.ToStateSpace();
  DiscreteSs minus_c = c;
  minus_c.C = -c.C;
  minus_c.D = -c.D;
  // F = C (T - 1): r -> (T - 1) r -> C.
  const DiscreteSs t_minus_1 = Blend(t, 1.0, StaticGain(1.0, design_.dt_s), -1.0);
  return {Series(t_minus_1, c), true, minus_c};
}

}  // namespace rths::control
