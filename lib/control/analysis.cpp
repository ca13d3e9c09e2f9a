#include "control/analysis.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

namespace rths::control {

namespace {

constexpr double kPi = std::numbers::pi;

std::complex<double> Loop(const DiscreteSs& fb, const DiscreteSs& plant, double f_hz) {
  return -fb.Response(f_hz) * plant.Response(f_hz);
}

double WrapDeg(double rad) {
  double deg = rad * 180.0 / kPi;
  while (deg > 180.0) deg -= 360.0;
  while (deg <= -180.0) deg += 360.0;
  return deg;
}

}  // namespace

LoopAnalysis AnalyzeLoop(const DiscreteSs& fb, const DiscreteSs& plant) {
  LoopAnalysis a;
  // Closed loop: plant x+ = Phi x + Gamma u, y = C x; controller xc+ = Ak xc + Bk y, u = Ck xc + Dk y.
  const int np = plant.order(), nc = fb.order();
  Eigen::MatrixXd acl(np + nc, np + nc);
  acl.topLeftCorner(np, np) = plant.A + fb.D * plant.B * plant.C;
  acl.topRightCorner(np, nc) = plant.B * fb.C;
  acl.bottomLeftCorner(nc, np) = fb.B * plant.C;
  acl.bottomRightCorner(nc, nc) = fb.A;
  a.closed_loop_poles = acl.eigenvalues();
  a.spectral_radius = a.closed_loop_poles.cwiseAbs().maxCoeff();
  a.stable = a.spectral_radius < 1.0;

  // Log grid from 1e-3 Hz to just below Nyquist; crossovers refined by bisection in log f.
  const double f_lo = 1e-3, f_hi = 0.5 / plant.dt_s * (1.0 - 1e-9);
  const int n = 8000;
  const auto f_at = [&](double t) { return f_lo * std::pow(f_hi / f_lo, t); };
  const auto gain_minus_1 = [&](double f) { return std::abs(Loop(fb, plant, f)) - 1.0; };
  double prev_t = 0.0, prev_g = gain_minus_1(f_lo);
  double peak = 0.0, peak_t = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double t = static_cast<double>(i) / n, f = f_at(t);
    const std::complex<double> l = Loop(fb, plant, f);
    const double g = std::abs(l) - 1.0, s = 1.0 / std::abs(1.0 + l);
    if (s > peak) peak = s, peak_t = t;
    if ((g > 0.0) != (prev_g > 0.0)) {
      double lo = prev_t, hi = t;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        ((gain_minus_1(f_at(mid)) > 0.0) == (prev_g > 0.0) ? lo : hi) = mid;
      }
      Crossover c;
      c.f_hz = f_at(0.5 * (lo + hi));
      c.phase_margin_deg = WrapDeg(kPi + std::arg(Loop(fb, plant, c.f_hz)));
      c.delay_margin_s = c.phase_margin_deg * kPi / 180.0 / (2.0 * kPi * c.f_hz);
      a.crossovers.push_back(c);
    }
    prev_t = t, prev_g = g;
  }
  // Refine the sensitivity peak by golden-section search on the neighbouring grid cells.
  double lo = std::max(0.0, peak_t - 1.0 / n), hi = std::min(1.0, peak_t + 1.0 / n);
  const auto sens = [&](double t) { return 1.0 / std::abs(1.0 + Loop(fb, plant, f_at(t))); };
  for (int it = 0; it < 60; ++it) {
    const double m1 = hi - 0.618 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    if (sens(m1) > sens(m2)) hi = m2; else lo = m1;
  }
  if (const double t = 0.5 * (lo + hi); sens(t) > peak) peak = sens(t), peak_t = t;
  a.peak_sensitivity_hz = f_at(peak_t);
  a.peak_sensitivity_db = 20.0 * std::log10(peak);
  if (!a.crossovers.empty()) {
    a.critical = *std::min_element(a.crossovers.begin(), a.crossovers.end(),
                                   [](const Crossover& x, const Crossover& y) { return x.delay_margin_s < y.delay_margin_s; });
  }
  return a;
}

std::complex<double> TrackingResponse(const ControllerLti& c, const DiscreteSs& plant, double f_hz) {
  const std::complex<double> g = plant.Response(f_hz), f = c.ff.Response(f_hz);
  if (!c.has_feedback) return f * g;
  const std::complex<double> k = c.fb.Response(f_hz);
  return g * (f - k) / (1.0 - k * g);
}

double TrackingLagS(const ControllerLti& c, const DiscreteSs& plant, double f_hz) {
  const double f0 = 0.01;
  const int n = 16 + static_cast<int>(std::ceil(8.0 * f_hz));
  std::complex<double> prev = TrackingResponse(c, plant, f0);
  double phase = std::arg(prev);
  for (int i = 1; i <= n; ++i) {
    const std::complex<double> h = TrackingResponse(c, plant, f0 + (f_hz - f0) * i / n);
    phase += std::arg(h / prev);
    prev = h;
  }
  return -phase / (2.0 * kPi * f_hz);
}

}  // namespace rths::control
