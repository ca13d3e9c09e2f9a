#include "signal/spectral.h"

#include <cmath>
#include <mutex>
#include <numbers>

#include <fftw3.h>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::signal {

namespace {

// FFTW's planner is not thread-safe (fftw_execute is): plans are made and destroyed under a lock.
std::mutex& PlannerMutex() {
  static std::mutex m;
  return m;
}

/// One r2c plan of length n with its own buffers; execute as often as needed.
class RealDftPlan {
 public:
  explicit RealDftPlan(std::size_t n) : n_(n) {
    in_ = fftw_alloc_real(n);
    out_ = fftw_alloc_complex(n / 2 + 1);
    if (!in_ || !out_) throw Error("RealDft", fmt::format("cannot allocate FFT buffers of length {}", n));
    std::lock_guard<std::mutex> lock(PlannerMutex());
    plan_ = fftw_plan_dft_r2c_1d(static_cast<int>(n), in_, out_, FFTW_ESTIMATE);
    if (!plan_) throw Error("RealDft", fmt::format("FFTW could not plan a transform of length {}", n));
  }
  ~RealDftPlan() {
    {
      std::lock_guard<std::mutex> lock(PlannerMutex());
      if (plan_) fftw_destroy_plan(plan_);
    }
    fftw_free(in_);
    fftw_free(out_);
  }
  RealDftPlan(const RealDftPlan&) = delete;
  RealDftPlan& operator=(const RealDftPlan&) = delete;

  double* in() { return in_; }
  std::complex<double> out(std::size_t i) const { return {out_[i][0], out_[i][1]}; }
  void Execute() { fftw_execute(plan_); }

 private:
  std::size_t n_;
  double* in_ = nullptr;
  fftw_complex* out_ = nullptr;
  fftw_plan plan_ = nullptr;
};

void CheckArgs(std::size_t nu, std::size_t ny, double dt_s, std::size_t segment_length) {
  if (nu != ny) throw Error("Welch", fmt::format("u and y differ in length ({} vs {} samples)", nu, ny));
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("Welch", fmt::format("dt_s must be > 0 (got {})", dt_s));
  if (segment_length < 4 || segment_length > nu)
    throw Error("Welch", fmt::format("segment length must be in [4, {}] samples (got {})", nu, segment_length));
}

}  // namespace

std::vector<std::complex<double>> RealDft(std::span<const double> x) {
  if (x.empty()) throw Error("RealDft", "empty input");
  RealDftPlan plan(x.size());
  for (std::size_t j = 0; j < x.size(); ++j) plan.in()[j] = x[j];
  plan.Execute();
  std::vector<std::complex<double>> X(x.size() / 2 + 1);
  for (std::size_t i = 0; i < X.size(); ++i) X[i] = plan.out(i);
  return X;
}

CrossSpectra WelchCrossSpectra(std::span<const double> u, std::span<const double> y, double dt_s,
                               std::size_t segment_length) {
  CheckArgs(u.size(), y.size(), dt_s, segment_length);
  const std::size_t L = segment_length, hop = L / 2, nf = L / 2 + 1;
  const std::size_t M = (u.size() - L) / hop + 1;

  std::vector<double> w(L);
  double w2 = 0.0;
  for (std::size_t j = 0; j < L; ++j) {
    w[j] = 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(L)));
    w2 += w[j] * w[j];
  }

  CrossSpectra s;
  s.fs_hz = 1.0 / dt_s;
  s.df_hz = s.fs_hz / static_cast<double>(L);
  s.segment_length = L;
  s.segments = M;
  s.f_hz.resize(nf);
  s.s_uu.assign(nf, 0.0);
  s.s_yy.assign(nf, 0.0);
  s.s_uy.assign(nf, {0.0, 0.0});
  for (std::size_t i = 0; i < nf; ++i) s.f_hz[i] = static_cast<double>(i) * s.df_hz;

  RealDftPlan pu(L), py(L);
  for (std::size_t m = 0; m < M; ++m) {
    const std::size_t o = m * hop;
    double mu = 0.0, my = 0.0;
    for (std::size_t j = 0; j < L; ++j) mu += u[o + j], my += y[o + j];
    mu /= static_cast<double>(L);
    my /= static_cast<double>(L);
    for (std::size_t j = 0; j < L; ++j) {
      pu.in()[j] = (u[o + j] - mu) * w[j];
      py.in()[j] = (y[o + j] - my) * w[j];
    }
    pu.Execute();
    py.Execute();
    for (std::size_t i = 0; i < nf; ++i) {
      const auto U = pu.out(i), Y = py.out(i);
      s.s_uu[i] += std::norm(U);
      s.s_yy[i] += std::norm(Y);
      s.s_uy[i] += std::conj(U) * Y;
    }
  }
  const double c = 1.0 / (s.fs_hz * w2 * static_cast<double>(M));
  for (std::size_t i = 0; i < nf; ++i) {
    const bool edge = i == 0 || (L % 2 == 0 && i == L / 2);
    const double a = edge ? c : 2.0 * c;
    s.s_uu[i] *= a;
    s.s_yy[i] *= a;
    s.s_uy[i] *= a;
  }
  return s;
}

std::vector<double> WelchPsd(std::span<const double> x, double dt_s, std::size_t segment_length) {
  return WelchCrossSpectra(x, x, dt_s, segment_length).s_uu;
}

FrequencyResponseEstimate H1FromSpectra(const CrossSpectra& s) {
  FrequencyResponseEstimate e;
  e.df_hz = s.df_hz;
  e.segments = s.segments;
  e.f_hz = s.f_hz;
  e.h.assign(s.f_hz.size(), {0.0, 0.0});
  e.coherence.assign(s.f_hz.size(), 0.0);
  for (std::size_t i = 0; i < s.f_hz.size(); ++i) {
    if (s.s_uu[i] > 0.0) e.h[i] = s.s_uy[i] / s.s_uu[i];
    const double d = s.s_uu[i] * s.s_yy[i];
    if (d > 0.0) e.coherence[i] = std::min(1.0, std::norm(s.s_uy[i]) / d);
  }
  return e;
}

FrequencyResponseEstimate H1Estimate(std::span<const double> u, std::span<const double> y, double dt_s,
                                     std::size_t segment_length) {
  return H1FromSpectra(WelchCrossSpectra(u, y, dt_s, segment_length));
}

std::vector<double> UnwrapPhase(std::span<const std::complex<double>> h) {
  std::vector<double> ph(h.size());
  if (h.empty()) return ph;
  ph[0] = std::arg(h[0]);
  for (std::size_t i = 1; i < h.size(); ++i) {
    double d = std::arg(h[i]) - std::arg(h[i - 1]);
    while (d > std::numbers::pi) d -= 2.0 * std::numbers::pi;
    while (d <= -std::numbers::pi) d += 2.0 * std::numbers::pi;
    ph[i] = ph[i - 1] + d;
  }
  return ph;
}

}  // namespace rths::signal
