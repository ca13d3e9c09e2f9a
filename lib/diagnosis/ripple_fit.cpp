#include "diagnosis/ripple_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>

#include <Eigen/Dense>

#include "signal/spectral.h"

namespace rths::diagnosis {

namespace {

constexpr int kH = models::kRippleHarmonics;
constexpr double kTwoPi = 2.0 * M_PI;

/// The 2 H regressors at sample k: sin and cos of 2 pi h f k dt, h = 1 .. H; 0 for a harmonic at
/// or above the Nyquist frequency (models::RippleHarmonicSampled).
void Regressors(double f_hz, double dt_s, std::size_t k, double* phi) {
  const double w = kTwoPi * f_hz * static_cast<double>(k) * dt_s;
  for (int h = 0; h < kH; ++h) {
    const bool on = models::RippleHarmonicSampled(h + 1, f_hz, dt_s);
    phi[2 * h] = on ? std::sin((h + 1) * w) : 0.0;
    phi[2 * h + 1] = on ? std::cos((h + 1) * w) : 0.0;
  }
}

/// The same regressors for k = first, first + 1, ... in order, by rotating a unit phasor
/// exp(i 2 pi f k dt) (a complex product per sample instead of 2 H sines and cosines), set exactly
/// every kResync samples so that rounding cannot accumulate.
class RegressorStream {
 public:
  RegressorStream(double f_hz, double dt_s, std::size_t first)
      : w_dt_(kTwoPi * f_hz * dt_s), step_(std::polar(1.0, w_dt_)), k_(first) {
    for (int h = 0; h < kH; ++h) on_[h] = models::RippleHarmonicSampled(h + 1, f_hz, dt_s) ? 1.0 : 0.0;
    Resync();
  }
  /// The regressors of the current sample, then moves to the next.
  void Next(double* phi) {
    std::complex<double> zh = z_;
    for (int h = 0; h < kH; ++h) {
      phi[2 * h] = on_[h] * zh.imag();
      phi[2 * h + 1] = on_[h] * zh.real();
      zh *= z_;
    }
    ++k_;
    if (k_ % kResync == 0) Resync();
    else z_ *= step_;
  }

 private:
  static constexpr std::size_t kResync = 256;
  void Resync() { z_ = std::polar(1.0, w_dt_ * static_cast<double>(k_)); }
  double w_dt_;
  std::complex<double> step_, z_;
  std::size_t k_;
  double on_[kH];
};

/// Adds the ripple with coefficients c at frequency f_hz, given its regressors phi at a sample, to
/// *y, and its rate and acceleration to *v, *a where not null: for s sin(w t) + c cos(w t),
/// w = 2 pi h f, the rate is w (s cos - c sin) and the acceleration -w^2 (s sin + c cos).
void AddHarmonics(const std::array<double, 2 * kH>& c, double f_hz, const double* phi, double* y, double* v,
                  double* a) {
  for (int h = 0; h < kH; ++h) {
    const double w = kTwoPi * (h + 1) * f_hz, sn = phi[2 * h], cs = phi[2 * h + 1];
    const double value = c[2 * h] * sn + c[2 * h + 1] * cs;
    *y += value;
    if (v != nullptr) *v += w * (c[2 * h] * cs - c[2 * h + 1] * sn);
    if (a != nullptr) *a -= w * w * value;
  }
}

}  // namespace

double RippleFit::FundamentalAmplitude() const { return std::hypot(coef[0], coef[1]); }

double RippleFit::Value(std::size_t k, double dt_s) const {
  double phi[2 * kH], y = 0.0;
  Regressors(f_hz, dt_s, k, phi);
  AddHarmonics(coef, f_hz, phi, &y, nullptr, nullptr);
  return y;
}

double RippleFit::Rate(std::size_t k, double dt_s) const {
  double phi[2 * kH], y = 0.0, v = 0.0;
  Regressors(f_hz, dt_s, k, phi);
  AddHarmonics(coef, f_hz, phi, &y, &v, nullptr);
  return v;
}

double RippleFit::Acceleration(std::size_t k, double dt_s) const {
  double phi[2 * kH], y = 0.0, a = 0.0;
  Regressors(f_hz, dt_s, k, phi);
  AddHarmonics(coef, f_hz, phi, &y, nullptr, &a);
  return a;
}

RippleFit FitRipple(std::span<const double> e, double dt_s, double f_hz, std::size_t first) {
  using Mat = Eigen::Matrix<double, 2 * kH, 2 * kH>;
  using Vec = Eigen::Matrix<double, 2 * kH, 1>;
  Mat g = Mat::Zero();
  Vec b = Vec::Zero();
  double phi[2 * kH];
  RegressorStream stream(f_hz, dt_s, first);
  for (std::size_t k = first; k < e.size(); ++k) {
    stream.Next(phi);
    const Eigen::Map<const Vec> p(phi);
    g.selfadjointView<Eigen::Lower>().rankUpdate(p);
    b += p * e[k];
  }
  g = g.selfadjointView<Eigen::Lower>();
  const double ridge = 1e-9 * std::max(g.trace() / (2 * kH), 1e-300);
  g.diagonal().array() += ridge;
  const Vec c = g.ldlt().solve(b);
  RippleFit r;
  r.f_hz = f_hz;
  for (int j = 0; j < 2 * kH; ++j) r.coef[j] = std::isfinite(c(j)) ? c(j) : 0.0;
  return r;
}

double RippleSse(std::span<const double> e, double dt_s, double f_hz, std::size_t first) {
  const RippleFit r = FitRipple(e, dt_s, f_hz, first);
  double s = 0.0, phi[2 * kH];
  RegressorStream stream(f_hz, dt_s, first);
  for (std::size_t k = first; k < e.size(); ++k) {
    stream.Next(phi);
    double d = e[k];
    for (int j = 0; j < 2 * kH; ++j) d -= r.coef[j] * phi[j];
    s += d * d;
  }
  return s;
}

void RippleFit::AddTo(double dt_s, std::span<double> y, std::span<double> v, std::span<double> a) const {
  double phi[2 * kH];
  RegressorStream stream(f_hz, dt_s, 0);
  for (std::size_t k = 0; k < y.size(); ++k) {
    stream.Next(phi);
    AddHarmonics(coef, f_hz, phi, &y[k], v.empty() ? nullptr : &v[k], a.empty() ? nullptr : &a[k]);
  }
}

double RipplePeakHz(const std::vector<std::vector<double>>& e, const std::vector<std::size_t>& first, double dt_s,
                    double lo_hz, double hi_hz) {
  std::size_t longest = 0;
  for (std::size_t r = 0; r < e.size(); ++r) longest = std::max(longest, e[r].size() - std::min(first[r], e[r].size()));
  std::size_t npad = 1;
  while (npad < 2 * longest) npad *= 2;
  const std::size_t nbins = npad / 2 + 1;
  std::vector<double> power(nbins, 0.0);
  std::vector<double> x(npad);
  for (std::size_t r = 0; r < e.size(); ++r) {
    const std::size_t k0 = std::min(first[r], e[r].size()), m = e[r].size() - k0;
    if (m < 4) continue;
    std::fill(x.begin(), x.end(), 0.0);
    for (std::size_t j = 0; j < m; ++j)
      x[j] = e[r][k0 + j] * 0.5 * (1.0 - std::cos(kTwoPi * static_cast<double>(j) / static_cast<double>(m)));
    const auto spec = signal::RealDft(x);
    for (std::size_t i = 0; i < nbins; ++i) power[i] += std::norm(spec[i]);
  }
  // Bin i is f_i = i / (npad dt); harmonic h of bin i is bin h i (below the Nyquist bin only).
  const double df = 1.0 / (static_cast<double>(npad) * dt_s);
  double best_f = lo_hz, best_p = -1.0;
  const auto i_lo = static_cast<std::size_t>(std::ceil(lo_hz / df));
  for (std::size_t i = std::max<std::size_t>(i_lo, 1); i < nbins && static_cast<double>(i) * df <= hi_hz; ++i) {
    double p = 0.0;
    for (int h = 1; h <= kH && static_cast<std::size_t>(h) * i < nbins - 1; ++h) p += power[static_cast<std::size_t>(h) * i];
    if (p > best_p) best_p = p, best_f = static_cast<double>(i) * df;
  }
  return best_f;
}

}  // namespace rths::diagnosis
