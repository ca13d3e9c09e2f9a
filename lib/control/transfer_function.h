#pragma once
/// @file SISO transfer functions as coefficient arrays, the way MATLAB's `tf` and `tfdata` write
/// them (descending powers of s or z), their discretisation (Tustin, zero-order hold), poles, and
/// the one recursion that runs a discrete one (docs/controllers.md, "A controller from transfer
/// functions"). Used by the `lti` controller; units are the caller's (mm -> mm there).
#include <array>
#include <complex>
#include <string>
#include <vector>

#include "control/controller_config.h"
#include "control/lti.h"

namespace rths::control {

/// Largest order (number of poles) of a transfer function the `lti` controller runs: its state
/// is a fixed-size array, so a step allocates nothing.
inline constexpr int kMaxTfOrder = 16;

/// A discrete transfer function at step dt_s, normalised so that a[0] = 1:
///   H(z) = (b_0 + b_1 z^-1 + ... + b_n z^-n) / (1 + a_1 z^-1 + ... + a_n z^-n),
/// b and a both of length n + 1 (n = order, the number of poles; n = 0: a static gain b_0).
struct DiscreteTf {
  std::vector<double> b{1.0};
  std::vector<double> a{1.0};
  double dt_s = 0.0;

  int order() const { return static_cast<int>(a.size()) - 1; }
  /// H(e^{j 2 pi f dt}).
  std::complex<double> Response(double f_hz) const;
  /// Poles (roots of z^n + a_1 z^{n-1} + ... + a_n), sorted by decreasing modulus.
  std::vector<std::complex<double>> Poles() const;
  /// Zeros (roots of b_0 z^n + ... + b_n, leading zeros dropped: a zero "at infinity" is none).
  std::vector<std::complex<double>> Zeros() const;
  /// A state-space realisation (observer canonical form of the recursion below), for analysis.
  DiscreteSs ToStateSpace() const;
};

/// The per-step state of a DiscreteTf run by FilterStep: the transposed direct form II delay line.
struct TfFilterState {
  std::array<double, kMaxTfOrder> w{};
};

/// One sample of y = H(z) x, the recursion of MATLAB's `filter` (transposed direct form II), in its
/// order of operations:
///   y = b_0 x + w_0;   w_i = (b_{i+1} x + w_{i+1}) - a_{i+1} y  (i = 0 .. n-2);   w_{n-1} = b_n x - a_n y.
/// Requires h.order() <= kMaxTfOrder. Allocates nothing.
inline double FilterStep(const DiscreteTf& h, TfFilterState* s, double x) {
  const int n = h.order();
  const double* b = h.b.data();
  const double* a = h.a.data();
  double* w = s->w.data();
  const double y = b[0] * x + (n > 0 ? w[0] : 0.0);
  for (int i = 0; i + 1 < n; ++i) w[i] = b[i + 1] * x + w[i + 1] - a[i + 1] * y;
  if (n > 0) w[n - 1] = b[n] * x - a[n] * y;
  return y;
}

/// Roots of a polynomial in descending powers (leading zeros dropped; eigenvalues of its companion
/// matrix). An all-zero or empty polynomial has no roots.
std::vector<std::complex<double>> PolynomialRoots(const std::vector<double>& descending);

/// Where a TfCoefficients is checked: the scenario key it came from (e.g. "controller.lti.feedback"),
/// for messages that name "<key>.num" or "<key>.den".
struct TfChecked {
  std::vector<double> num;  ///< leading zeros dropped
  std::vector<double> den;  ///< leading zeros dropped, den[0] != 0
};
/// Refuses, with rths::Error("<key>.num" / "<key>.den", ...), an empty array, a coefficient that is
/// not finite, an all-zero denominator, more than kMaxTfOrder poles, and an improper function
/// (degree of num above degree of den: it would need future samples).
TfChecked CheckTf(const TfCoefficients& tf, const std::string& key);

/// Tustin (bilinear) discretisation, s = (2/dt) (z - 1)/(z + 1), no prewarping (MATLAB's
/// c2d(sys, dt, 'tustin')): num and den multiplied by (z + 1)^n, n = degree of den.
DiscreteTf TustinTf(const TfChecked& s, double dt_s);
/// Zero-order-hold discretisation (MATLAB's c2d(sys, dt, 'zoh')): the controllable canonical
/// realisation of num/den discretised exactly (control::ZohDiscretise), back to coefficients by
///   a(z) = det(zI - Phi),   b(z) = det(zI - Phi + Gamma C) - det(zI - Phi) + D det(zI - Phi).
DiscreteTf ZohTf(const TfChecked& s, double dt_s);
/// A transfer function given in z (descending powers of z, as tfdata prints it): num padded on the
/// left to den's length and both divided by den's leading coefficient.
DiscreteTf ZDomainTf(const TfChecked& z, double dt_s);

/// A pole within this distance of z = 1 counts as an integrator (a pole at s = 0 maps to z = 1
/// exactly under Tustin and ZOH; coefficients typed from a printout land within it).
inline constexpr double kIntegratorTolerance = 1e-6;

/// Pole counts of a discrete transfer function (stability as the `lti` controller judges it): stable
/// when every pole has |z| < 1 except at most one integrator (a simple pole at z = 1, s = 0, as in a
/// PI); two integrators or any other pole on or outside the unit circle make it unstable.
struct TfStability {
  int integrators = 0;  ///< poles with |z - 1| <= kIntegratorTolerance
  int unstable = 0;     ///< other poles with |z| >= 1
  double spectral_radius = 0.0;  ///< largest |z| of all poles
  bool Stable() const { return integrators <= 1 && unstable == 0; }
};
TfStability StabilityOf(const DiscreteTf& h);

}  // namespace rths::control
