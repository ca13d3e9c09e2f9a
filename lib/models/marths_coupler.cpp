#include "models/marths_coupler.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace rths::models::marths {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

double CouplerGeometry::d_m(int i) const { return std::sqrt(xv_m[i] * xv_m[i] + yv_m[i] * yv_m[i]); }
double CouplerGeometry::alpha_rad(int i) const { return alpha_deg[i] * kPi / 180.0; }

StrokeDifference StrokeDifferenceOf(const CouplerGeometry& g) {
  return {g.d1_m() * std::cos(g.alpha1_rad()) - g.d2_m() * std::cos(g.alpha2_rad()),
          g.d1_m() * std::sin(g.alpha1_rad()) - g.d2_m() * std::sin(g.alpha2_rad())};
}

std::string CouplerProblem(const CouplerGeometry& g, InverseForm form) {
  for (int i = 0; i < 2; ++i) {
    if (!std::isfinite(g.xv_m[i]) || !std::isfinite(g.yv_m[i]) || !std::isfinite(g.alpha_deg[i])) {
      return fmt::format("arm {}: a value that is not finite", i + 1);
    }
    if (!(g.d_m(i) >= 1e-3)) return fmt::format("arm {} is {} m long; at least 0.001 m", i + 1, g.d_m(i));
    const double at = std::atan2(g.yv_m[i], g.xv_m[i]) * 180.0 / kPi;
    if (!(std::abs(at - g.alpha_deg[i]) <= 1e-3)) {
      return fmt::format("arm {}: alpha = {} deg but atan2(yv, xv) = {:.6f} deg (they must agree within 0.001 deg)",
                         i + 1, g.alpha_deg[i], at);
    }
  }
  // d(x_1 - x_2)/d(theta) at theta = 0 is -Q: the stroke difference must see a small rotation.
  const double Q = StrokeDifferenceOf(g).Q_m;
  if (!(std::abs(Q) >= 0.01 * std::max(g.d1_m(), g.d2_m()))) {
    return fmt::format("the arms' ends are {} m apart vertically (yv_1 - yv_2), under 1 % of the longer arm: the "
                       "strokes' difference does not see a small rotation",
                       Q);
  }
  if (form == InverseForm::kAsWired && (g.d1_m() != g.d2_m() || g.alpha_deg[0] != -g.alpha_deg[1])) {
    return "the as-wired inverse is the reference code's formula for symmetric arms (d_1 = d_2, alpha_1 = "
           "-alpha_2); use inverse = \"exact\" for these arms";
  }
  return "";
}

ActuatorPair Forward(const CouplerGeometry& g, const InterfaceMotion& m) {
  ActuatorPair a;
  a.a1_mm = 1000.0 * (m.x_m + g.d1_m() * (std::cos(m.theta_rad + g.alpha1_rad()) - std::cos(g.alpha1_rad())));
  a.a2_mm = 1000.0 * (m.x_m + g.d2_m() * (std::cos(m.theta_rad + g.alpha2_rad()) - std::cos(g.alpha2_rad())));
  return a;
}

InterfaceMotion Inverse(const CouplerGeometry& g, const ActuatorPair& a, InverseForm form) {
  const double x1 = a.a1_mm / 1000.0, x2 = a.a2_mm / 1000.0;
  const double d1 = g.d1_m(), al1 = g.alpha1_rad();
  InterfaceMotion m;
  double angle = 0.0;  // what goes inside the cosine of the translation
  if (form == InverseForm::kAsWired) {
    const double r = (x1 - x2) / (2.0 * g.d2_m() * std::sin(g.alpha2_rad()));
    m.theta_rad = std::asin(r);
    angle = r;
  } else {
    const auto [P, Q] = StrokeDifferenceOf(g);
    const double phi = std::atan2(P, -Q);
    const double s = std::asin((x1 - x2 + P) / std::hypot(P, Q));
    const double near = std::remainder(s - phi, 2.0 * kPi);
    const double far = std::remainder(kPi - s - phi, 2.0 * kPi);
    m.theta_rad = std::abs(far) < std::abs(near) ? far : near;
    angle = m.theta_rad;
  }
  m.x_m = x1 - d1 * (std::cos(al1 + angle) - std::cos(al1));
  return m;
}

}  // namespace rths::models::marths
