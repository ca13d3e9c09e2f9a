#pragma once
/// @file Fitting the servohydraulic model of Eq. 15 to a measured frequency response
/// (docs/experiments.md E1, docs/identification.md).
///
/// Model (Eq. 15, no time delay): G(s) = K / prod_{i=1..N} (s - p_i), kept in factored form
///     G(s) = K / ( (s + p)^[N odd] prod_{j=1..floor(N/2)} (s^2 + b_j s + c_j) ),
/// with K, p, b_j, c_j > 0. Every factor with positive coefficients is Hurwitz, so the fitted
/// poles are stable by construction (a quadratic factor holds a complex pair or two real poles).
/// For N = 3 this is the paper's K / ((s + p)(s^2 + b s + c)) of Eqs. 28-30 (models::ServoModel3).
///
/// Fit, on the points f_k of the band [lo, hi] with weights w_k (from the coherence gamma_k^2):
///   1. linear start (Levy, refined by Sanathanan-Koerner iterations): with s' = j w / w0,
///      w0 = 2 pi hi, solve min sum_k w_k |K' - H_k D'(s'_k)|^2 / (|H_k|^2 |D'_prev(s'_k)|^2) for
///      K' and the monic D'(s') = s'^N + d'_{N-1} s'^{N-1} + ... + d'_0 (linear least squares);
///      its roots, reflected into the left half plane, give the factors;
///   2. Levenberg-Marquardt on theta = ln[K, p, b_j, c_j] (positivity = stability; each rate p, b_j,
///      sqrt(c_j) kept within 1e-3 .. 1e3 x 2 pi hi by projecting the step) minimising
///      the weighted relative complex error
///        J(theta) = sum_k w_k |G(j 2 pi f_k) - H_k|^2 / |H_k|^2  /  sum_k w_k.
///   With zoh_dt_s > 0, G(j w) is replaced by the response of G's zero-order-hold
///   discretisation at step zoh_dt_s, C (zI - Phi)^-1 Gamma at z = e^{j w dt}: the continuous
///   model whose ZOH simulation reproduces the data (the hold's half-sample lag is not absorbed
///   into the poles).
#include <complex>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenario/scenario.h"

namespace rths::ident {

/// Eq. 15 in factored, stable form (see the file comment). Units: u and y in mm, s in 1/s.
struct PoleModel {
  double K = 0.0;                               ///< gain [1/s^N]
  double p = 0.0;                               ///< real pole at s = -p [1/s] (odd N; 0 for even N)
  std::vector<double> b;                        ///< s^2 + b_j s + c_j: b_j [1/s]
  std::vector<double> c;                        ///< c_j [1/s^2]; dim b.size()

  /// N = (p > 0 ? 1 : 0) + 2 b.size().
  int Order() const;
  /// Continuous G(j 2 pi f) [mm/mm].
  std::complex<double> Response(double f_hz) const;
  /// The N poles p_i [1/s] (real pole first, then each factor's pair).
  std::vector<std::complex<double>> Poles() const;
  /// Expanded denominator prod (s - p_i) = d_0 + d_1 s + ... + d_N s^N, coefficients d_0..d_N
  /// (d_N = 1).
  std::vector<double> Denominator() const;
  /// Static gain G(0) = K / d_0 [mm/mm].
  double DcGain() const;
  /// Low-frequency time lag -d phase / d w at w = 0: d_1 / d_0 [s].
  double DcLagS() const;
  /// The N = 3 model as K, p, b, c (name "custom"). Throws rths::Error unless N = 3.
  models::ServoModel3 ToServoModel3() const;
  static PoleModel FromServoModel3(const models::ServoModel3& m);
};

/// Zero-order-hold discretisation of a PoleModel: x_{k+1} = Phi x_k + Gamma u_k, y_k = C x_k, in a
/// well-scaled cascade realisation (first-order section, then one 2-state section per quadratic
/// factor, states [q, q'/sqrt(c_j)]; K in C). Exact (augmented matrix exponential).
struct ZohModel {
  double dt_s = 0.0;            ///< hold step [s]
  Eigen::MatrixXd Phi;          ///< e^{A dt}, dim N x N
  Eigen::VectorXd Gamma;        ///< int_0^dt e^{A s} ds B, dim N
  Eigen::RowVectorXd C;         ///< output row, dim N
};
/// Throws rths::Error unless every coefficient is finite and > 0 and dt_s > 0.
ZohModel Discretise(const PoleModel& m, double dt_s);
/// C (zI - Phi)^-1 Gamma at z = e^{j 2 pi f dt} [mm/mm].
std::complex<double> ZohResponse(const ZohModel& d, double f_hz);
/// y_k = C x_k for k = 0 .. n-1, from rest (x_0 = 0), with u_k held over [t_k, t_{k+1}): y_k
/// depends on u_0 .. u_{k-1} only (docs/lockstep.md pairing). Units of u [mm] -> y [mm].
std::vector<double> SimulateZoh(const ZohModel& d, std::span<const double> u);

/// How the coherence gamma^2 weights each frequency point of the fit.
enum class Weighting {
  kCoherence,        ///< w = gamma^2
  kInverseVariance,  ///< w = gamma^2 / (1 - gamma^2), gamma^2 capped at 0.999 (the H1 relative
                     ///< variance is (1 - gamma^2) / (2 M gamma^2))
  kUniform,          ///< w = 1
};

/// Options of FitPoleModel; defaults are those of `rths identify`.
struct FitOptions {
  int poles = 3;                 ///< N, [1, 8]
  double band_lo_hz = 0.5;       ///< lowest frequency fitted [Hz], >= 0
  double band_hi_hz = 40.0;      ///< highest frequency fitted [Hz], > band_lo_hz (paper: up to 40 Hz)
  Weighting weighting = Weighting::kInverseVariance;
  double zoh_dt_s = 0.0;         ///< > 0: fit the ZOH-discretised model at this step (file comment)
  int max_iterations = 300;      ///< Levenberg-Marquardt iterations, [1, 100000]
  /// True if every field is in range; else false and a message naming the field.
  bool IsValid(std::string* error) const;
};

/// The fitted model and how well it fits.
struct FitSummary {
  PoleModel model;
  PoleModel linear_start;             ///< step 1's model (before Levenberg-Marquardt)
  std::size_t points = 0;             ///< frequency points in the band with w > 0
  double rms_rel_error = 0.0;         ///< sqrt(mean_k |G_k - H_k|^2 / |H_k|^2) over the band, unweighted
  double weighted_rms_rel_error = 0;  ///< sqrt(J) at the optimum
  double max_mag_error_pct = 0.0;     ///< max_k | |G_k| / |H_k| - 1 | x 100 over the band
  double max_phase_error_deg = 0.0;   ///< max_k |arg(G_k / H_k)| over the band [deg]
  int iterations = 0;                 ///< Levenberg-Marquardt iterations taken
  bool converged = false;             ///< step or cost change below tolerance before max_iterations
  /// Multi-line text: the model, its poles, DC gain and lag, the fit error.
  std::string Report() const;
};

/// Fits Eq. 15 to H_k = h[k] at f_k = f_hz[k] with coherence gamma^2_k (file comment). Points
/// outside the band, at f = 0, with H_k = 0 or with gamma^2_k = 0 are left out (a caller leaves
/// out a point by zeroing its coherence).
/// Throws rths::Error if the spans differ in length, options are invalid, or fewer than
/// 2 (N + 1) points with w > 0 lie in the band.
FitSummary FitPoleModel(std::span<const double> f_hz, std::span<const std::complex<double>> h,
                        std::span<const double> coherence, const FitOptions& options);

}  // namespace rths::ident
