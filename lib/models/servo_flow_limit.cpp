#include "models/servo_flow_limit.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

FlowLimitedServo FlowLimitedServo::Make(const ServoModel3& m, double vmax_mm_s, double dt_s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(m.K) || !positive(m.p) || !positive(m.b) || !positive(m.c) || !positive(vmax_mm_s) || !positive(dt_s))
    throw Error("FlowLimitedServo", fmt::format("K, p, b, c, vmax and dt must be finite and > 0 (got K = {}, p = {}, "
                                                "b = {}, c = {}, vmax = {} mm/s, dt = {} s)",
                                                m.K, m.p, m.b, m.c, vmax_mm_s, dt_s));
  return {m.K, m.p, m.b, m.c, vmax_mm_s, dt_s, LinearServo::Make(m, dt_s)};
}

FlowLimitedServo FlowLimitedServo::Make(const LinearServo& l, double vmax_mm_s) {
  ServoModel3 m;
  m.K = l.K, m.p = l.p, m.b = l.b, m.c = l.c;
  return Make(m, vmax_mm_s, l.dt_s);
}

double Velocity(const FlowLimitedServo& m, const FlowLimitedServoState& s) {
  return std::clamp(s.xv, -m.vmax_mm_s, m.vmax_mm_s);
}

double Acceleration(const FlowLimitedServo& m, const FlowLimitedServoState& s) {
  return std::abs(s.xv) < m.vmax_mm_s ? s.w - m.b * s.xv - m.c * s.x : 0.0;
}

void Derivative(const FlowLimitedServo& m, const double* st, double u_mm, double* d) {
  d[0] = -m.p * st[0] + m.K * u_mm;
  d[1] = std::clamp(st[2], -m.vmax_mm_s, m.vmax_mm_s);
  d[2] = st[0] - m.b * st[2] - m.c * st[1];
}

void Step(const FlowLimitedServo& m, FlowLimitedServoState* s, double u_mm) {
  const double lim = kLinearStepMargin * m.vmax_mm_s;
  if (std::abs(s->xv) < lim) {
    // Below the limit: the exact ZOH in phase variables, kept if it stays below at the end.
    LinearServoState z;
    z.z << s->x, s->xv, s->w - m.b * s->xv - m.c * s->x;
    models::Step(m.linear, &z, u_mm);
    if (std::abs(z.z(1)) < lim) {
      s->x = z.z(0), s->xv = z.z(1), s->w = z.z(2) + m.b * z.z(1) + m.c * z.z(0);
      return;
    }
  }
  const double h = m.dt_s / kFlowLimitSubsteps;
  double y[3] = {s->w, s->x, s->xv};
  for (int j = 0; j < kFlowLimitSubsteps; ++j) {
    double k1[3], k2[3], k3[3], k4[3], t[3];
    Derivative(m, y, u_mm, k1);
    for (int q = 0; q < 3; ++q) t[q] = y[q] + 0.5 * h * k1[q];
    Derivative(m, t, u_mm, k2);
    for (int q = 0; q < 3; ++q) t[q] = y[q] + 0.5 * h * k2[q];
    Derivative(m, t, u_mm, k3);
    for (int q = 0; q < 3; ++q) t[q] = y[q] + h * k3[q];
    Derivative(m, t, u_mm, k4);
    for (int q = 0; q < 3; ++q) y[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
  }
  s->w = y[0], s->x = y[1], s->xv = y[2];
}

}  // namespace rths::models
