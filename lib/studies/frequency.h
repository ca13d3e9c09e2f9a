#pragma once
/// @file What the frequency-domain studies share (Fig. 6, E1: G_yu; Figs. 7-8, E2: G_yr): the
/// excitation and scenario of a run (a predefined BLWN 0-50 Hz desired displacement), frequency
/// responses as the paper plots them, their figure and CSV. Spectra by Welch / H1
/// (signal/spectral.h), fits by ident/fit.h.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "ident/actuator_fit.h"
#include "ident/fit.h"
#include "io/plot.h"
#include "scenario/scenario.h"
#include "signal/bode.h"
#include "signal/spectral.h"
#include "studies/study.h"

namespace rths::studies {

/// E1 and E2's constants: BLWN 0-50 Hz, RMS 0.254 mm, 60 s records (--quick 16 s), faded in over
/// 0.5 s, at 2 kHz; the fits over 0.5-40 Hz (the paper: models accurate up to 40 Hz); plots to 50 Hz.
inline constexpr double kFreqBandHz = 50.0;
inline constexpr double kFreqRmsMm = 0.254;
inline constexpr double kFreqFullS = 60.0;
inline constexpr double kFreqQuickS = 16.0;
inline constexpr double kFreqTaperS = 0.5;
inline constexpr double kFreqFitLoHz = 0.5, kFreqFitHiHz = 40.0;
inline constexpr double kFreqPlotMaxHz = 50.0;
inline constexpr double kFreqDtS = 0.0005;

/// A frequency response as the paper plots it (signal/bode.h); a model's by ident::BodeFromModel.
using signal::BodeCurve;
using signal::BodeFromEstimate;
using ident::BodeFromModel;

/// The excitation of E1 and E2: BLWN 0-50 Hz, RMS 0.254 mm, seed 1, 2 s discarded, faded in over
/// 0.5 s (the command of E1; the desired displacement of E2).
signal::SignalSpec FrequencyExcitation();

/// The scenario of one frequency-domain run (E1, E2): desired r = BLWN 0-50 Hz, RMS 0.254 mm,
/// seed 1, faded in over 0.5 s; the damper attached at the condition's constant current
/// ("0.0A" or "2.5A"); the plant ("linear": Eq. 28 or 29).
scenario::Scenario FrequencyScenario(const std::string& condition, const control::ControllerConfig& controller,
                                     const std::string& plant, double duration_s);

/// The skeleton's batch step for E1 and E2: RunStudyBatch with one line per run; throws
/// rths::Error naming every run that failed.
std::vector<RunResult> RunFrequencyBatch(std::vector<RunSpec> specs, const ReproduceOptions& opts,
                                         const std::string& what);

/// The Bode figure (io/bode_figure.h) of Figs. 6-8: three stacked panels (magnitude, phase, time
/// lag, its axis over the curves from 2 Hz up) for a set of curves: `solid` in their controller's
/// style (studies/figures.h; `proposed` drawn prominent, other names in palette order), then
/// `styled` as given. One legend, beside the magnitude panel; the same margins in all three panels
/// so their frequency axes line up.
io::Figure BodeFigure(const std::string& name, const std::string& title, const std::vector<BodeCurve>& solid,
                      const std::vector<std::pair<BodeCurve, io::Series>>& styled, const std::string& proposed = "");

/// Writes the curves as `key_column`,f_hz,magnitude,phase_deg,time_lag_ms,coherence.
void WriteCurvesCsv(const std::filesystem::path& file, const std::string& key_column,
                    const std::vector<BodeCurve>& curves);

/// Calls f(i) for every point i of the curve in [lo, hi] Hz.
template <typename F>
void ForEachIn(const BodeCurve& c, double lo, double hi, F f) {
  for (std::size_t i = 0; i < c.f_hz.size(); ++i) {
    if (c.f_hz[i] >= lo && c.f_hz[i] <= hi) f(i);
  }
}
/// Linear interpolation of a curve's column at f [Hz] (NaN above the grid).
double ValueAt(const BodeCurve& c, const std::vector<double>& col, double f);

}  // namespace rths::studies
