#include "diagnosis/residual_stats.h"

#include <algorithm>
#include <cmath>

#include "diagnosis/tuning.h"
#include "signal/spectral.h"

namespace rths::diagnosis::stages {

double SumSq(std::span<const double> m, std::size_t first) {
  double s = 0;
  for (std::size_t k = first; k < m.size(); ++k) s += m[k] * m[k];
  return s;
}

double IntegratedCorrelationTime(const Channel& ch, const std::vector<std::vector<double>>& pred) {
  std::vector<double> acc;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    if (n < 16) continue;
    // Linear autocorrelation by FFT of the zero-padded residual: R = IDFT(|X|^2); for a real
    // even sequence the inverse DFT is the forward DFT / N.
    std::size_t N = 1;
    while (N < 2 * n) N <<= 1;
    std::vector<double> e(N, 0.0);
    double mean = 0;
    for (std::size_t k = 0; k < n; ++k) mean += meas[d.first + k] - pred[r][d.first + k];
    mean /= static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = meas[d.first + k] - pred[r][d.first + k] - mean;
    const auto X = signal::RealDft(e);
    std::vector<double> p(N);
    for (std::size_t j = 0; j < N; ++j) {
      const auto& x = j <= N / 2 ? X[j] : X[N - j];
      p[j] = std::norm(x);
    }
    const auto R = signal::RealDft(p);
    const std::size_t L = std::min<std::size_t>(static_cast<std::size_t>(tuning::kCorrelationMaxLag) + 1,
                                                n / static_cast<std::size_t>(tuning::kCorrelationLagDivisor));
    if (acc.size() < L) acc.resize(L, 0.0);
    for (std::size_t l = 0; l < L; ++l) acc[l] += R[l].real() / static_cast<double>(N);
  }
  if (acc.empty() || acc[0] <= 0) return 1.0;
  double tau = 1.0;
  for (std::size_t l = 1; l < acc.size(); ++l) {
    const double rl = acc[l] / acc[0];
    if (rl <= 0) break;
    tau += 2.0 * rl;
  }
  return tau;
}

/// Noise floor of a residual set: the level of the residual PSD's plateau above the excitation,
/// sigma^2 = f_Nyq x max(median PSD over [lo, split] f_Nyq, median PSD over [split, hi] f_Nyq)
/// (o.noise_band_lo, o.noise_band_split, o.noise_band_hi), PSDs (Welch, segments of
/// tuning::kNoisePsdSegment samples) of the records averaged with weights by their length. For white

double NoiseFloorVar(const Channel& ch, const std::vector<std::vector<double>>& pred, const Options& o) {
  std::vector<double> psd;
  double wsum = 0;
  double nyq = 0;
  std::size_t L = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    L = std::min<std::size_t>(static_cast<std::size_t>(tuning::kNoisePsdSegment), n);
    nyq = 0.5 / d.dt;
    std::vector<double> e(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = meas[d.first + k] - pred[r][d.first + k];
    const auto p = signal::WelchPsd(e, d.dt, L);
    if (psd.empty()) psd.assign(p.size(), 0.0);
    if (p.size() != psd.size()) continue;
    for (std::size_t j = 0; j < p.size(); ++j) psd[j] += static_cast<double>(n) * p[j];
    wsum += static_cast<double>(n);
  }
  if (psd.empty() || wsum <= 0) return 0.0;
  const double df = 2.0 * nyq / static_cast<double>(L);
  auto median = [&](double lo, double hi) {
    std::vector<double> band;
    for (std::size_t j = 0; j < psd.size(); ++j) {
      const double f = static_cast<double>(j) * df;
      if (f >= lo * nyq && f <= hi * nyq) band.push_back(psd[j] / wsum);
    }
    if (band.empty()) return 0.0;
    std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2), band.end());
    return band[band.size() / 2];
  };
  return nyq * std::max(median(o.noise_band_lo, o.noise_band_split), median(o.noise_band_split, o.noise_band_hi));
}

double Whiteness(const Channel& ch, const std::vector<std::vector<double>>& pred) {
  const int L = tuning::kWhitenessLags;
  std::vector<double> c(L + 1, 0.0);
  double n_tot = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    std::vector<double> e(n);
    double mean = 0;
    for (std::size_t k = 0; k < n; ++k) mean += (e[k] = meas[d.first + k] - pred[r][d.first + k]);
    mean /= static_cast<double>(n);
    for (double& x : e) x -= mean;
    for (int l = 0; l <= L; ++l)
      for (std::size_t k = static_cast<std::size_t>(l); k < n; ++k) c[l] += e[k] * e[k - l];
    n_tot += static_cast<double>(n);
  }
  if (c[0] <= 0) return 0.0;
  double q = 0;
  for (int l = 1; l <= L; ++l) q += (c[l] / c[0]) * (c[l] / c[0]);
  return n_tot * q;
}

}  // namespace rths::diagnosis::stages
