#pragma once
/// @file Welch spectral estimates and the H1 frequency-response estimator (docs/experiments.md E1,
/// docs/identification.md). Offline analysis only: these functions allocate.
///
/// Conventions, for two records u_k, y_k (k = 0 .. n-1) at step dt [s], fs = 1/dt:
///   - segments of L samples, hop L/2 (50 % overlap), the last partial segment dropped:
///     M = floor((n - L) / (L/2)) + 1 segments;
///   - each segment has its own mean removed, then is multiplied by the periodic Hann window
///     w_j = 0.5 (1 - cos(2 pi j / L)), j = 0 .. L-1;
///   - U_m(f_i) = sum_j w_j u_{mL/2+j} e^{-2 pi i j i / L} at f_i = i fs / L, i = 0 .. L/2;
///   - one-sided densities, averaged over segments, with the scale c = 1 / (fs sum_j w_j^2):
///       S_uu(f_i) = a_i c mean_m |U_m|^2,   S_uy(f_i) = a_i c mean_m conj(U_m) Y_m,
///     a_i = 1 at DC and (for even L) at Nyquist, a_i = 2 between. Units: [unit_u^2 / Hz],
///     [unit_u unit_y / Hz]. With this scale sum_i S_uu(f_i) df (df = fs / L) is the mean
///     square of the windowed, mean-free segments (Parseval), i.e. the variance of a
///     stationary u;
///   - H1 estimator: G_yu(f) = S_uy(f) / S_uu(f) (unbiased under noise on y);
///   - ordinary coherence: gamma^2(f) = |S_uy|^2 / (S_uu S_yy), in [0, 1]; 1 for a noise-free
///     linear system, lower with noise or nonlinearity (needs M > 1 segments to mean anything).
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace rths::signal {

/// Discrete Fourier transform of a real sequence x_j, j = 0 .. n-1 (n >= 1, any length):
/// X_i = sum_j x_j e^{-2 pi i j i / n} for i = 0 .. n/2 (the other half is conj-symmetric).
/// Computed with FFTW (r2c, FFTW_ESTIMATE). Parseval: sum_j x_j^2 = (1/n) sum_{i=0}^{n-1} |X_i|^2.
std::vector<std::complex<double>> RealDft(std::span<const double> x);

/// Auto- and cross-spectral densities of u and y by Welch's method (conventions above).
struct CrossSpectra {
  double fs_hz = 0.0;                     ///< sample rate 1/dt [Hz]
  double df_hz = 0.0;                     ///< frequency step fs / L [Hz]
  std::size_t segment_length = 0;         ///< L [samples]
  std::size_t segments = 0;               ///< M, segments averaged
  std::vector<double> f_hz;               ///< f_i = i df, i = 0 .. L/2 [Hz]
  std::vector<double> s_uu;               ///< S_uu(f_i) [unit_u^2 / Hz]
  std::vector<double> s_yy;               ///< S_yy(f_i) [unit_y^2 / Hz]
  std::vector<std::complex<double>> s_uy; ///< S_uy(f_i) = E[conj(U) Y] [unit_u unit_y / Hz]
};

/// Welch estimate of S_uu, S_yy and S_uy. Throws rths::Error unless u and y have the same
/// length n, dt_s > 0, 4 <= segment_length <= n.
CrossSpectra WelchCrossSpectra(std::span<const double> u, std::span<const double> y, double dt_s,
                               std::size_t segment_length);

/// Welch auto-spectral density of x alone (the S_uu of WelchCrossSpectra(x, x, ...)), one value
/// per f_i = i fs / L, i = 0 .. L/2 [unit^2 / Hz]. Same preconditions.
std::vector<double> WelchPsd(std::span<const double> x, double dt_s, std::size_t segment_length);

/// Frequency response estimate G_yu(j 2 pi f) from input u to output y, with its coherence.
struct FrequencyResponseEstimate {
  double df_hz = 0.0;                     ///< frequency step [Hz]
  std::size_t segments = 0;               ///< segments averaged
  std::vector<double> f_hz;               ///< f_i [Hz], i = 0 .. L/2
  std::vector<std::complex<double>> h;    ///< H1 = S_uy / S_uu [unit_y / unit_u] (0 where S_uu = 0)
  std::vector<double> coherence;          ///< gamma^2 in [0, 1] (0 where S_uu S_yy = 0)
};

/// H1 estimate and coherence from Welch spectra (conventions above); same preconditions as
/// WelchCrossSpectra.
FrequencyResponseEstimate H1Estimate(std::span<const double> u, std::span<const double> y, double dt_s,
                                     std::size_t segment_length);
/// The same from spectra already computed.
FrequencyResponseEstimate H1FromSpectra(const CrossSpectra& s);

/// Phase of h_i unwrapped along the grid, starting from the principal value at i = 0 [rad]:
/// consecutive differences are brought into (-pi, pi].
std::vector<double> UnwrapPhase(std::span<const std::complex<double>> h);

}  // namespace rths::signal
