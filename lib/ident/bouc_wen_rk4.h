#pragma once
/// @file How the damper fits integrate the Bouc-Wen model's internal state (y, z) between two
/// samples (damper_fit.h SimulateDamperForce, spencer_fit.cpp): classical RK4 in m equal substeps,
/// the motion (and the coefficients) linear in time across the sample step, m from a bound of the
/// stiffest rate (damper_fit.h "substeps").
#include <cmath>

namespace rths::ident {

/// The bound lambda [1/s] of the Bouc-Wen model's rates: 2 sqrt(A (beta + gamma)) |x'| (the
/// evolutionary variable z's) plus `slow` = (A alpha + k0) / (c0 + c1) (the internal
/// displacement y's); A [-], beta + gamma [1/mm^2], vmax [mm/s].
inline double BoucWenRateBound(double A, double beta_plus_gamma, double vmax_mm_s, double slow_1_s) {
  return 2.0 * std::sqrt(A * beta_plus_gamma) * vmax_mm_s + slow_1_s;
}

/// RK4 substeps for a sample step dt [s] at rate bound lambda [1/s]: ceil(dt lambda / 0.8), the
/// step h = dt / m within RK4's region (h lambda <= 0.8). Unclamped (the caller bounds it).
inline double SubstepsFor(double dt_s, double lambda_1_s) { return std::ceil(dt_s * lambda_1_s / 0.8); }

/// m RK4 substeps of the state (*y [mm], *z [mm]) across one sample step of dt [s];
/// `rates(s, y, z, &ydot, &zdot)` gives the rates [mm/s] at the fraction s in [0, 1] of the step.
template <typename Rates>
void Rk4Substeps(int m, double dt_s, double* y, double* z, Rates&& rates) {
  const double h = dt_s / m;
  for (int i = 0; i < m; ++i) {
    const double s0 = static_cast<double>(i) / m, s1 = (i + 0.5) / m, s2 = static_cast<double>(i + 1) / m;
    double dy1, dz1, dy2, dz2, dy3, dz3, dy4, dz4;
    rates(s0, *y, *z, &dy1, &dz1);
    rates(s1, *y + 0.5 * h * dy1, *z + 0.5 * h * dz1, &dy2, &dz2);
    rates(s1, *y + 0.5 * h * dy2, *z + 0.5 * h * dz2, &dy3, &dz3);
    rates(s2, *y + h * dy3, *z + h * dz3, &dy4, &dz4);
    *y += h / 6.0 * (dy1 + 2.0 * dy2 + 2.0 * dy3 + dy4);
    *z += h / 6.0 * (dz1 + 2.0 * dz2 + 2.0 * dz3 + dz4);
  }
}

}  // namespace rths::ident
