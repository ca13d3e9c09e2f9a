#include "control/feedforward.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/derivative.h"

namespace rths::control {

FeedforwardCoefficients MakeFeedforwardCoefficients(const models::ServoModel3& m) {
  const auto check = [&](const char* name, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw Error(fmt::format("servo model \"{}\": {}", m.name, name),
                  fmt::format("{} = {}: allowed > 0 (finite; a stable, minimum-phase model)", name, v));
    }
  };
  check("K", m.K);
  check("p", m.p);
  check("b", m.b);
  check("c", m.c);
  FeedforwardCoefficients a;
  a.a3 = 1.0 / m.K;
  a.a2 = (m.p + m.b) / m.K;
  a.a1 = (m.p * m.b + m.c) / m.K;
  a.a0 = m.p * m.c / m.K;
  return a;
}

Derivatives ExtrapolateDerivatives(const ExtrapolationState& past, double r_i, double dt_s) {
  const double dt2 = dt_s * dt_s;
  Derivatives d;
  d.r = r_i;
  d.acc_prev = (r_i - 2.0 * past.r1 + past.r2) / dt2;                     // a_{i-1}
  const double acc_prev2 = (past.r1 - 2.0 * past.r2 + past.r3) / dt2;     // a_{i-2}
  d.vel_prev = (r_i - past.r2) / (2.0 * dt_s);                            // v_{i-1}
  d.rdd = 2.0 * d.acc_prev - acc_prev2;                                   // Eq. 20
  d.rd = d.vel_prev + 0.5 * dt_s * (d.acc_prev + d.rdd);                  // Eq. 21
  d.rddd = (d.acc_prev - acc_prev2) / dt_s;                               // Eq. 22
  return d;
}

void PushDisplacement(ExtrapolationState* state, double r_i) {
  state->r3 = state->r2;
  state->r2 = state->r1;
  state->r1 = r_i;
}

Derivatives StepDerivatives(ExtrapolationState* state, double r_i, double dt_s) {
  const Derivatives d = ExtrapolateDerivatives(*state, r_i, dt_s);
  PushDisplacement(state, r_i);
  return d;
}

DerivativeRecords CentralDerivatives(const std::vector<double>& r, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw Error("CentralDerivatives", fmt::format("dt = {}: allowed > 0", dt));
  }
  const std::size_t n = r.size();
  DerivativeRecords d;
  // r' by signal::Derivative, its one-sided ends set to zero as the other derivatives' are.
  d.rd = signal::Derivative(r, dt);
  if (n > 0) d.rd.front() = d.rd.back() = 0.0;
  d.rdd.assign(n, 0.0);
  d.rddd.assign(n, 0.0);
  const double dt2 = dt * dt;
  const double dt3 = dt2 * dt;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    d.rdd[i] = (r[i + 1] - 2.0 * r[i] + r[i - 1]) / dt2;
  }
  for (std::size_t i = 2; i + 2 < n; ++i) {
    d.rddd[i] = (r[i + 2] - 2.0 * r[i + 1] + 2.0 * r[i - 1] - r[i - 2]) / (2.0 * dt3);
  }
  return d;
}

double FeedforwardCommand(const FeedforwardCoefficients& a, const Derivatives& d, bool half_step_ahead,
                          double dt) {
  if (!half_step_ahead) return a.a0 * d.r + a.a1 * d.rd + a.a2 * d.rdd + a.a3 * d.rddd;  // Eq. 19
  const double h = 0.5 * dt;
  return a.a0 * (d.r + h * d.rd) + a.a1 * (d.rd + h * d.rdd) + a.a2 * (d.rdd + h * d.rddd) +
         a.a3 * d.rddd;
}

}  // namespace rths::control
