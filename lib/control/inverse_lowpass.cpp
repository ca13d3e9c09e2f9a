#include "control/inverse_lowpass.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {

using cd = std::complex<double>;

/// One analog section (n2 s^2 + n1 s + n0) / (m2 s^2 + m1 s + m0).
struct AnalogSection {
  double n2, n1, n0, m2, m1, m0;
  cd At(cd s) const { return (n2 * s * s + n1 * s + n0) / (m2 * s * s + m1 * s + m0); }
};

/// Tustin s = c (1 - z^-1)/(1 + z^-1), c = 2/dt, multiplied through by (1 + z^-1)^2, or by
/// (1 + z^-1) for a first-order section (n2 = m2 = 0), normalised to a leading 1 in the denominator.
signal::Biquad Tustin(const AnalogSection& a, double c) {
  const double c2 = c * c;
  if (a.n2 == 0.0 && a.m2 == 0.0) {
    const double a0 = a.m1 * c + a.m0;
    return {(a.n1 * c + a.n0) / a0, (a.n0 - a.n1 * c) / a0, 0.0, (a.m0 - a.m1 * c) / a0, 0.0};
  }
  const double a0 = a.m2 * c2 + a.m1 * c + a.m0;
  return {(a.n2 * c2 + a.n1 * c + a.n0) / a0, (2.0 * a.n0 - 2.0 * a.n2 * c2) / a0,
          (a.n2 * c2 - a.n1 * c + a.n0) / a0, (2.0 * a.m0 - 2.0 * a.m2 * c2) / a0,
          (a.m2 * c2 - a.m1 * c + a.m0) / a0};
}

/// The analog sections of LP(s) G^-1(s), each with unit DC gain except the first (gain p c / K).
std::vector<AnalogSection> AnalogSections(const models::ServoModel3& m, int order, double wc) {
  const double pi = std::numbers::pi;
  std::vector<AnalogSection> out;
  const double w2 = wc * wc;
  // Butterworth pairs s^2 + q_k w_c s + w_c^2, least damped (k = 0) first.
  std::vector<double> q;
  for (int k = 0; k < order / 2; ++k) q.push_back(2.0 * std::sin((2.0 * k + 1.0) * pi / (2.0 * order)));
  // (s^2 + b s + c) / (s^2 + q_0 w_c s + w_c^2), DC gain 1.
  out.push_back({w2 / m.c, m.b * w2 / m.c, w2, 1.0, q[0] * wc, w2});
  std::size_t next = 1;
  if (order % 2 == 1) {
    out.push_back({0.0, wc / m.p, wc, 0.0, 1.0, wc});  // (s + p) / (s + w_c) x w_c / p
  } else {
    out.push_back({0.0, w2 / m.p, w2, 1.0, q[next] * wc, w2});  // (s + p) / pair x w_c^2 / p
    ++next;
  }
  for (; next < q.size(); ++next) out.push_back({0.0, 0.0, w2, 1.0, q[next] * wc, w2});
  const double dc = m.p * m.c / m.K;  // 1 / G(0)
  out[0].n2 *= dc, out[0].n1 *= dc, out[0].n0 *= dc;
  return out;
}

}  // namespace

cd InverseLowpassDesign::Analog(double f_hz) const {
  const cd s(0.0, 2.0 * std::numbers::pi * f_hz);
  cd h = 1.0;
  for (const AnalogSection& a : AnalogSections(model, order, 2.0 * std::numbers::pi * cutoff_hz)) h *= a.At(s);
  return h;
}

InverseLowpassDesign MakeInverseLowpass(const models::ServoModel3& model, int order, double cutoff_hz,
                                        double dt_s, const std::string& key) {
  RequireServoModel(model, key);
  if (order < 3 || order > 8) {
    throw Error("controller.lp_order",
                fmt::format("{}: allowed [3, 8] (the three-pole inverse needs order >= 3 to be proper)", order));
  }
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  if (!(cutoff_hz > 0.0) || !(cutoff_hz < 0.5 / dt_s)) {
    throw Error("controller.lp_cutoff_hz",
                fmt::format("{} Hz: allowed (0, {}) (below the Nyquist frequency)", cutoff_hz, 0.5 / dt_s));
  }
  InverseLowpassDesign d;
  d.model = model;
  d.order = order;
  d.cutoff_hz = cutoff_hz;
  d.dt_s = dt_s;
  const double wc = 2.0 * std::numbers::pi * cutoff_hz;
  double sum_re = order % 2 == 1 ? wc : 0.0;  // sum of -Re(pole)
  for (int k = 0; k < order / 2; ++k) sum_re += 2.0 * wc * std::sin((2.0 * k + 1.0) * std::numbers::pi / (2.0 * order));
  d.dc_group_delay_s = sum_re / (wc * wc);
  for (const AnalogSection& a : AnalogSections(model, order, wc)) {
    const signal::Biquad q = Tustin(a, 2.0 / dt_s);
    // Stable iff both roots of z^2 + a1 z + a2 lie inside the unit circle (Jury).
    if (!(std::abs(q.a2) < 1.0 && std::abs(q.a1) < 1.0 + q.a2)) {
      throw Error(key, fmt::format("the discretised LP G^-1 has a section with poles on or outside the unit "
                                   "circle (a1 = {}, a2 = {})",
                                   q.a1, q.a2));
    }
    d.sos.sections.push_back(q);
  }
  return d;
}

InverseLowpass::InverseLowpass(InverseLowpassDesign design)
    : design_(std::move(design)), state_(signal::SosAtRest(design_.sos)) {}

Command InverseLowpass::Step(const Derivatives& d, const Measurement&) {
  const double u = signal::SosStep(design_.sos, &state_, d.r);
  return {u, u, 0.0};
}

ControllerLti InverseLowpass::Linearize(double) const { return {FromSos(design_.sos, design_.dt_s), false, {}}; }

BumplessInverseLowpass::BumplessInverseLowpass(InverseLowpassDesign low, InverseLowpassDesign high,
                                               double current_high_A)
    : low_(std::move(low)),
      high_(std::move(high)),
      current_high_A_(current_high_A),
      state_low_(signal::SosAtRest(low_.sos)),
      state_high_(signal::SosAtRest(high_.sos)) {
  if (!(current_high_A > 0.0) || !std::isfinite(current_high_A)) {
    throw Error("controller.current_high_A", fmt::format("{} A: allowed > 0", current_high_A));
  }
  if (low_.dt_s != high_.dt_s) throw Error("controller", "bumpless_lp: the two designs differ in dt");
}

double BumplessInverseLowpass::Lambda(double current_A) const {
  return std::clamp(current_A / current_high_A_, 0.0, 1.0);
}

Command BumplessInverseLowpass::Step(const Derivatives& d, const Measurement& m) {
  const double u_low = signal::SosStep(low_.sos, &state_low_, d.r);
  const double u_high = signal::SosStep(high_.sos, &state_high_, d.r);
  const double lambda = Lambda(m.current_A);  // a NaN current propagates to u
  const double u = (1.0 - lambda) * u_low + lambda * u_high;
  return {u, u, 0.0};
}

ControllerLti BumplessInverseLowpass::Linearize(double current_A) const {
  const double lambda = Lambda(current_A);
  return {Blend(FromSos(low_.sos, low_.dt_s), 1.0 - lambda, FromSos(high_.sos, high_.dt_s), lambda), false, {}};
}

}  // namespace rths::control
