#pragma once
/// @file A frequency response as the paper plots it (Figs. 6-8): magnitude, unwrapped phase and
/// time lag on a grid of frequencies, from an H1 estimate (spectral.h) or from any complex
/// response on a grid (a fitted model's: ident/actuator_fit.h). The one place the phase is
/// unwrapped and turned into a time lag for a figure: `rths identify`'s Bode plot, the
/// frequency-domain studies (studies/frequency.h).
#include <complex>
#include <span>
#include <string>
#include <vector>

#include "signal/spectral.h"

namespace rths::signal {

/// A measured or modelled frequency response on a grid.
struct BodeCurve {
  std::string name;                 ///< legend entry
  std::vector<double> f_hz;         ///< frequencies [Hz], > 0
  std::vector<double> magnitude;    ///< |G| [output unit / input unit, e.g. mm/mm]
  std::vector<double> phase_deg;    ///< unwrapped phase [deg] (UnwrapPhase, from the first point up)
  std::vector<double> lag_ms;       ///< time lag -phase / (2 pi f) [ms] (> 0: the output lags)
  std::vector<double> coherence;    ///< gamma^2 [-] (1 for a model)
};

/// The curve of the responses h at f_hz (ascending, h's length), phase unwrapped from the first
/// point up; `coherence` of the same length, or empty for a model (then 1 everywhere). The time lag
/// of a point at f = 0 is not finite (a curve unwrapped from DC: BodeBand drops it). Throws
/// rths::Error if the lengths differ.
BodeCurve BodeFromResponse(const std::string& name, std::span<const double> f_hz,
                           std::span<const std::complex<double>> h, std::span<const double> coherence = {});

/// The points of c with lo_hz <= f <= hi_hz and f > 0, in order (the phase as unwrapped in c).
BodeCurve BodeBand(const BodeCurve& c, double lo_hz, double hi_hz);

/// The H1 estimate on (0, f_max_hz], phase unwrapped from the lowest frequency up.
BodeCurve BodeFromEstimate(const std::string& name, const FrequencyResponseEstimate& est, double f_max_hz);

}  // namespace rths::signal
