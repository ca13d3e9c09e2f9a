#pragma once
/// @file Identification of the servohydraulic model from a record of command u and measured y
/// (`rths identify`, docs/experiments.md E1, docs/identification.md):
///   1. G_yu(f) by the H1 estimator with coherence (signal/spectral.h, Welch, Hann, 50 %);
///   2. Eq. 15 fitted over a band by ident::FitPoleModel (ident/fit.h), leaving out the points
///      where the input has (next to) no power;
///   3. a time-domain check: the fitted model, discretised with a zero-order hold at the record's
///      step, simulated on the record's u from rest; Eq. 31 with the measured y in the role of r:
///        e = sqrt( sum_k (y_k - yhat_k)^2 / sum_k y_k^2 ) x 100 %,
///      beside the same number for the identity model yhat = u (no actuator dynamics).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "ident/fit.h"
#include "signal/spectral.h"

namespace rths::ident {

/// Options of Identify; defaults are those of `rths identify`.
struct IdentifyOptions {
  FitOptions fit{};          ///< band, poles, weighting, ZOH
  double segment_s = 0.0;    ///< Welch segment length [s]; 0 = DefaultSegmentLength
  /// Points of the band where the input was not excited, S_uu(f) < min_excitation x max S_uu over
  /// the band, are left out of the fit (their H1 is leakage and noise), [0, 1).
  double min_excitation = 1e-3;
};

/// Welch segment length [samples]: round(segment_s / dt_s) if segment_s > 0, else
/// min(4 s, 2 n / 9 samples) (4 s gives df = 0.25 Hz; the cap keeps at least 8 segments),
/// at least 16 samples and at most n.
std::size_t DefaultSegmentLength(std::size_t n, double dt_s, double segment_s);

/// The time-domain check (file comment) over samples [first, last) of a simulation from k = 0.
struct Prediction {
  std::vector<double> y_mm;            ///< simulated yhat_k for every k [mm]
  double model_error_pct = 0.0;        ///< Eq. 31, measured y vs the model over [first, last)
  double identity_error_pct = 0.0;     ///< Eq. 31, measured y vs u over [first, last)
};
/// Simulates Discretise(model, dt_s) on u (from rest, y_k from u_0 .. u_{k-1}) and scores
/// [first, last). Throws rths::Error if u and y differ in length or the window is empty.
Prediction PredictDisplacement(const PoleModel& model, double dt_s, std::span<const double> u_mm,
                               std::span<const double> y_mm, std::size_t first, std::size_t last);

/// Everything `rths identify` prints.
struct IdentifyResult {
  double dt_s = 0.0;                         ///< record step [s]
  std::size_t samples = 0;                   ///< record length
  std::size_t segment_length = 0;            ///< Welch segment [samples]
  IdentifyOptions options{};
  signal::FrequencyResponseEstimate frf;     ///< H1 and coherence on the Welch grid
  std::vector<double> s_uu;                  ///< input auto-spectrum on the same grid [mm^2/Hz]
  std::size_t unexcited_points = 0;          ///< band points left out for S_uu below the threshold
  double fitted_lo_hz = 0.0, fitted_hi_hz = 0.0;  ///< lowest and highest frequency fitted [Hz]
  FitSummary fit;                            ///< the fitted model
  Prediction prediction;                     ///< over the whole record
  /// Human-readable summary: estimate, model, fit error, DC gain and lag, time-domain check.
  std::string Report() const;
};

/// Steps 1-3 on u, y at step dt_s. Throws rths::Error for mismatched lengths, too short a record
/// for the segment, or whatever FitPoleModel throws.
IdentifyResult Identify(std::span<const double> u_mm, std::span<const double> y_mm, double dt_s,
                        const IdentifyOptions& options);

/// The scenario fragment `rths identify` prints and writes, from the two fits of one record:
///     [run]
///     dt_s = ..                                       <- the record's step
///     [plant]
///     actuator = { K = .., p = .., b = .., c = .. }   <- `zoh`: its ZOH simulation at the record's
///                                                       dt reproduces the record (a plant to simulate)
///     [controller]
///     model = { K = .., p = .., b = .., c = .. }      <- `continuous`: Eq. 15 fitted to the measured
///                                                       G_yu, hold lag included (a design model)
/// with '#' comments giving each fit's errors, DC gain and lag; `title` is the first comment line.
/// Models of another order than 3 come out as comments only (scenarios hold 3-pole models).
std::string ScenarioFragment(const IdentifyResult& continuous, const IdentifyResult& zoh, const std::string& title);

}  // namespace rths::ident
