#include "control/mimo_feedforward.h"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {

/// A polynomial by ascending powers of s.
using Poly = std::vector<double>;

Poly Mul(const Poly& a, const Poly& b) {
  Poly c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

Poly Scaled(Poly a, double k) {
  for (double& v : a) v *= k;
  return a;
}

/// num = q den + r, deg r < deg den (den's leading coefficient non-zero).
void Divide(Poly num, const Poly& den, Poly* q, Poly* r) {
  const std::size_t nd = den.size() - 1;
  q->assign(num.size() > nd ? num.size() - nd : 1, 0.0);
  for (std::size_t i = num.size(); i-- > nd;) {
    const double c = num[i] / den[nd];
    (*q)[i - nd] = c;
    for (std::size_t j = 0; j <= nd; ++j) num[i - nd + j] -= c * den[j];
  }
  r->assign(num.begin(), num.begin() + static_cast<long>(nd));
}

TfChecked Descending(const Poly& num, const Poly& den) {
  TfChecked t;
  t.num.assign(num.rbegin(), num.rend());
  t.den.assign(den.rbegin(), den.rend());
  while (t.num.size() > 1 && t.num.front() == 0.0) t.num.erase(t.num.begin());
  return t;
}

}  // namespace

MimoFeedforward MakeMimoFeedforward(const models::marths::PlantZpk& p, double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("mimo_ff", "dt_s must be > 0");
  const auto d1a = models::marths::ColumnDenominator(p, 0), d2a = models::marths::ColumnDenominator(p, 1);
  const Poly d1(d1a.begin(), d1a.end()), d2(d2a.begin(), d2a.end());
  // q(s) = k11 k22 (s - z22) - k21 k12 (s - z12): the transmission zero other than z1, z2.
  const Poly q = {-(p.k11 * p.k22 * p.h22z1 - p.k21 * p.k12 * p.h12z1), p.k11 * p.k22 - p.k21 * p.k12};
  const double zq = -q[0] / q[1];
  for (double z : {p.h1z1, p.h1z2, zq}) {
    if (!(z < 0.0)) {
      throw Error("mimo_ff", fmt::format("the plant has a transmission zero at {:.4g} rad/s, not in the left half "
                                         "plane: its inverse would be unstable", z));
    }
  }
  const Poly zz = {p.h1z1 * p.h1z2, -(p.h1z1 + p.h1z2), 1.0};  // (s - z1)(s - z2)
  const Poly row1_den = Mul(zz, q);
  const Poly num[2][2] = {{Mul(d1, Scaled({-p.h22z1, 1.0}, p.k22)), Mul(d1, Scaled({-p.h12z1, 1.0}, -p.k12))},
                          {Scaled(d2, -p.k21), Scaled(d2, p.k11)}};
  const Poly* den[2] = {&row1_den, &q};
  MimoFeedforward f;
  f.dt_s = dt_s;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      Poly quotient, rest;
      Divide(num[i][j], *den[i], &quotient, &rest);
      if (quotient.size() > 4) throw Error("mimo_ff", "the inverse needs more than three derivatives");
      for (std::size_t m = 0; m < quotient.size(); ++m) f.q[i][j][m] = quotient[m];
      f.rest[i][j] = TustinTf(Descending(rest, *den[i]), dt_s);
    }
  }
  return f;
}

Eigen::Vector2d MimoFeedforwardStep(const MimoFeedforward& f, MimoFeedforwardState* s, double target1_mm,
                                    double target2_mm) {
  const double x[2] = {target1_mm, target2_mm};
  Derivatives d[2];
  for (int j = 0; j < 2; ++j) d[j] = StepDerivatives(&s->targets[j], x[j], f.dt_s);
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const auto& c = f.q[i][j];
      u(i) += c[0] * d[j].r + c[1] * d[j].rd + c[2] * d[j].rdd + c[3] * d[j].rddd;
      u(i) += FilterStep(f.rest[i][j], &s->rest[i][j], x[j]);
    }
  }
  return u;
}

}  // namespace rths::control
