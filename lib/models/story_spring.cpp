#include "models/story_spring.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {
namespace {

void Require(bool ok, const char* field, const char* range, double got) {
  if (!ok) throw Error(field, fmt::format("must be in {} (got {})", range, got));
}

// Bouc-Wen right-hand side in u: (dz/du, dE_h/du).
struct BwRates {
  double dz, de;
};
BwRates BoucWenRates(const SpringParams& p, double z, double e, double sgn_du) {
  const double g = BoucWenSlope(p, z, e, sgn_du);
  return {g, (1.0 - p.alpha) * p.k_kN_per_mm * z * (1.0 - g)};
}

SpringTrial BoucWen(const SpringParams& p, const SpringState& c, double u) {
  const double du = u - c.u_mm;
  double z = c.z_mm, e = c.energy_kN_mm;
  const double sgn = du >= 0.0 ? 1.0 : -1.0;
  if (du != 0.0) {
    const double per = p.x_y_mm / kBoucWenStepsPerYield;
    const int m = static_cast<int>(std::clamp(std::ceil(std::abs(du) / per), 1.0,
                                              static_cast<double>(kBoucWenMaxSubsteps)));
    const double h = du / m;
    for (int i = 0; i < m; ++i) {  // classical RK4 in u
      const BwRates k1 = BoucWenRates(p, z, e, sgn);
      const BwRates k2 = BoucWenRates(p, z + 0.5 * h * k1.dz, e + 0.5 * h * k1.de, sgn);
      const BwRates k3 = BoucWenRates(p, z + 0.5 * h * k2.dz, e + 0.5 * h * k2.de, sgn);
      const BwRates k4 = BoucWenRates(p, z + h * k3.dz, e + h * k3.de, sgn);
      z += h / 6.0 * (k1.dz + 2.0 * k2.dz + 2.0 * k3.dz + k4.dz);
      e += h / 6.0 * (k1.de + 2.0 * k2.de + 2.0 * k3.de + k4.de);
    }
  }
  const double k = p.k_kN_per_mm, a = p.alpha;
  SpringTrial t;
  t.state = {u, z, e};
  t.force_kN = a * k * u + (1.0 - a) * k * z;
  t.tangent_kN_per_mm = k * (a + (1.0 - a) * BoucWenSlope(p, z, e, sgn));
  return t;
}

SpringTrial Bilinear(const SpringParams& p, const SpringState& c, double u) {
  const double k = p.k_kN_per_mm, b = p.b, u_y = p.f_y_kN / k;
  const double z_trial = c.z_mm + (u - c.u_mm);
  SpringTrial t;
  t.state = c;
  t.state.u_mm = u;
  t.tangent_kN_per_mm = k;
  t.state.z_mm = z_trial;
  if (std::abs(z_trial) > u_y) {  // return mapping of the elastic-perfectly-plastic part
    t.state.z_mm = std::copysign(u_y, z_trial);
    t.state.energy_kN_mm += (1.0 - b) * k * u_y * (std::abs(z_trial) - u_y);
    t.tangent_kN_per_mm = b * k;
  }
  t.force_kN = b * k * u + (1.0 - b) * k * t.state.z_mm;
  return t;
}

}  // namespace

void SpringParams::Validate() const {
  Require(k_kN_per_mm > 0.0 && k_kN_per_mm <= 1e9, "k_kN_per_mm", "(0, 1e9]", k_kN_per_mm);
  if (kind == SpringKind::kBoucWen) {
    Require(alpha >= 0.0 && alpha < 1.0, "alpha", "[0, 1)", alpha);
    Require(x_y_mm > 0.0 && x_y_mm <= 1e6, "x_y_mm", "(0, 1e6]", x_y_mm);
    Require(n >= 1.0 && n <= 20.0, "n", "[1, 20]", n);
    Require(beta >= 0.0 && beta <= 10.0, "beta", "[0, 10]", beta);
    Require(gamma >= -10.0 && gamma <= 10.0, "gamma", "[-10, 10]", gamma);
    if (!(beta >= std::abs(gamma) && beta + gamma > 0.0))
      throw Error("gamma", fmt::format("must satisfy |gamma| <= beta and beta + gamma > 0 "
                                       "(got beta = {}, gamma = {})",
                                       beta, gamma));
    Require(delta_nu >= 0.0 && delta_nu <= 10.0, "delta_nu", "[0, 10]", delta_nu);
    Require(delta_eta >= 0.0 && delta_eta <= 10.0, "delta_eta", "[0, 10]", delta_eta);
  } else if (kind == SpringKind::kBilinear) {
    Require(b >= 0.0 && b < 1.0, "b", "[0, 1)", b);
    Require(f_y_kN > 0.0 && f_y_kN <= 1e9, "f_y_kN", "(0, 1e9]", f_y_kN);
  }
}

double SpringParams::YieldDisplacement() const {
  switch (kind) {
    case SpringKind::kBoucWen: return x_y_mm;
    case SpringKind::kBilinear: return f_y_kN / k_kN_per_mm;
    case SpringKind::kLinear: break;
  }
  return 0.0;
}

double SpringParams::PostYieldRatio() const {
  switch (kind) {
    case SpringKind::kBoucWen: return alpha;
    case SpringKind::kBilinear: return b;
    case SpringKind::kLinear: break;
  }
  return 1.0;
}

double BoucWenSlope(const SpringParams& p, double z, double e, double sgn_du) {
  const double r = std::abs(z) / p.x_y_mm;
  const double rn = p.n == 1.0 ? r : (p.n == 2.0 ? r * r : std::pow(r, p.n));
  const double s = sgn_du * z >= 0.0 ? 1.0 : -1.0;  // sgn(du z); the term vanishes at z = 0
  const double eps = e / (p.k_kN_per_mm * p.x_y_mm * p.x_y_mm);
  const double nu = 1.0 + p.delta_nu * eps, eta = 1.0 + p.delta_eta * eps;
  return (1.0 - nu * (p.beta * s + p.gamma) * rn) / eta;  // A = 1
}

SpringTrial EvaluateSpring(const SpringParams& p, const SpringState& c, double u) {
  switch (p.kind) {
    case SpringKind::kBoucWen: return BoucWen(p, c, u);
    case SpringKind::kBilinear: return Bilinear(p, c, u);
    case SpringKind::kLinear: break;
  }
  SpringTrial t;
  t.state = {u, 0.0, 0.0};
  t.force_kN = p.k_kN_per_mm * u;
  t.tangent_kN_per_mm = p.k_kN_per_mm;
  return t;
}

}  // namespace rths::models
