#include "control/baselines.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {
void RequirePositive(const char* key, double v, const char* unit, double scale) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw Error(key, fmt::format("{} {}: allowed > 0 (finite)", v * scale, unit));
  }
}
}  // namespace

Poly3Design MakePoly3(double delay_s, double dt_s) {
  RequirePositive("controller.delay_ms", delay_s, "ms", 1e3);
  RequirePositive("run.dt_s", dt_s, "s", 1.0);
  Poly3Design d;
  d.delay_s = delay_s;
  const double a = d.alpha = delay_s / dt_s;
  d.c = {(a + 1) * (a + 2) * (a + 3) / 6.0, -a * (a + 2) * (a + 3) / 2.0, a * (a + 1) * (a + 3) / 2.0,
         -a * (a + 1) * (a + 2) / 6.0};
  d.nyquist_gain = std::abs(d.c[0] - d.c[1] + d.c[2] - d.c[3]);
  return d;
}

Command PolynomialExtrapolation::Step(const Derivatives& d, const Measurement&) {
  const auto& c = design_.c;
  const double u = c[0] * d.r + c[1] * past_[0] + c[2] * past_[1] + c[3] * past_[2];
  past_ = {d.r, past_[0], past_[1]};
  return {u, u, 0.0};
}

ControllerLti PolynomialExtrapolation::Linearize(double) const {
  return {Fir(Eigen::Vector4d(design_.c[0], design_.c[1], design_.c[2], design_.c[3]), dt_s_), false, {}};
}

LeadDesign MakeLead(double delay_s, double tp_s, double dt_s) {
  RequirePositive("controller.delay_ms", delay_s, "ms", 1e3);
  RequirePositive("controller.lead_tp_ms", tp_s, "ms", 1e3);
  RequirePositive("run.dt_s", dt_s, "s", 1.0);
  LeadDesign d;
  d.delay_s = delay_s;
  d.tp_s = tp_s;
  d.tz_s = delay_s + tp_s;
  const double c = 2.0 / dt_s;
  const double den = c * tp_s + 1.0;
  d.b0 = (c * d.tz_s + 1.0) / den;
  d.b1 = (1.0 - c * d.tz_s) / den;
  d.a1 = (1.0 - c * tp_s) / den;
  return d;
}

Command LeadCompensator::Step(const Derivatives& d, const Measurement&) {
  const double u = design_.b0 * d.r + design_.b1 * r_prev_ - design_.a1 * u_prev_;
  r_prev_ = d.r;
  u_prev_ = u;
  return {u, u, 0.0};
}

ControllerLti LeadCompensator::Linearize(double) const {
  signal::Sos sos;
  sos.sections.push_back({design_.b0, design_.b1, 0.0, design_.a1, 0.0});
  return {FromSos(sos, dt_s_), false, {}};
}

}  // namespace rths::control
