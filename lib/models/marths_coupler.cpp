#include "models/marths_coupler.h"

#include <cmath>

namespace rths::models::marths {

double CouplerGeometry::d1_m() const { return std::sqrt(xv1_m * xv1_m + yv1_m * yv1_m); }
double CouplerGeometry::d2_m() const { return std::sqrt(xv2_m * xv2_m + yv2_m * yv2_m); }

ActuatorPair Forward(const CouplerGeometry& g, const InterfaceMotion& m) {
  ActuatorPair a;
  a.a1_mm = 1000.0 * (m.x_m + g.d1_m() * (std::cos(m.theta_rad + g.alpha1_rad) - std::cos(g.alpha1_rad)));
  a.a2_mm = 1000.0 * (m.x_m + g.d2_m() * (std::cos(m.theta_rad + g.alpha2_rad) - std::cos(g.alpha2_rad)));
  return a;
}

InterfaceMotion Inverse(const CouplerGeometry& g, const ActuatorPair& a, InverseForm form) {
  const double x1 = a.a1_mm / 1000.0, x2 = a.a2_mm / 1000.0;
  const double r = (x1 - x2) / (2.0 * g.d2_m() * std::sin(g.alpha2_rad));
  InterfaceMotion m;
  m.theta_rad = std::asin(r);
  const double angle = form == InverseForm::kAsWired ? r : m.theta_rad;
  m.x_m = x1 - g.d1_m() * (std::cos(g.alpha1_rad + angle) - std::cos(g.alpha1_rad));
  return m;
}

}  // namespace rths::models::marths
