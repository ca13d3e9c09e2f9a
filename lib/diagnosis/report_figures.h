#pragma once
/// @file The figures of the diagnosis report (report.h), built but not plotted: WriteReport plots
/// them with io::Plot; tests check their ranges, masks and styles.
///
/// Conventions (io/plot.h): units of docs/units.md ("Frequency [Hz]", "Time [s]", y [mm], f [kN]),
/// io::ReadableColors() (measured blue, nominal model vermillion dashed, with the verdict's effects
/// bluish green dotted), every legend outside the axes on the right.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "io/plot.h"

namespace rths::diagnosis {

/// Points of the FRF figure whose coherence u -> y_meas is below this are left out: at gamma^2 =
/// 0.5 the noise (or nonlinear) part of y's power equals the part linear in u (gamma^2 = S / (S + N)),
/// so below it the measured response is mostly not a response to u.
inline constexpr double kFrfMinCoherence = 0.5;

/// The fraction of a one-sided spectrum's energy the FRF figure's frequency axis covers: the
/// input's 99 % energy band, from its 0.5 % to its 99.5 % cumulative energy ...
inline constexpr double kFrfEnergyFraction = 0.99;
/// ... counting only the frequencies where the input's density is within 30 dB of its peak and
/// y_meas follows it (coherence >= kFrfMinCoherence): a measured command's noise and
/// interference excite nothing the rig answers, yet can hold more than 1 % of the energy (UTFSM's
/// chirp_0A: a 284 Hz line of about 0.2 mm on a 1.4 mm rms 8-20 Hz chirp, coherence 0.3).
inline constexpr double kFrfInputFloor = 1e-3;

/// The band [lo, hi] [Hz] holding the central `fraction` of the energy of the density `psd` on the
/// grid f_hz (DC left out): lo where the cumulative energy reaches (1 - fraction) / 2, hi where it
/// reaches (1 + fraction) / 2 (the grid points). Throws rths::Error if the sizes differ, fraction
/// is not in (0, 1] or the spectrum holds no energy.
std::pair<double, double> EnergyBand(const std::vector<double>& f_hz, const std::vector<double>& psd,
                                     double fraction);

/// PSD of the measured channel ("y" or "f") and of its residual under the nominal model and with
/// the verdict's effects, log-log, samples from `first` on.
io::Figure SpectrumFigure(const Traces::Record& t, const std::string& channel, std::size_t first);

/// G_yu measured and modelled (H1 from u, samples from `first` on): magnitude, phase and the
/// coherence u -> y_meas. The frequency axis spans the input's excited band (EnergyBand of S_uu
/// with kFrfEnergyFraction, over the frequencies where S_uu >= kFrfInputFloor x its peak and the
/// coherence is at least kFrfMinCoherence (if there are none, S_uu's alone); from
/// 0 Hz if the band starts below a quarter of its top); magnitude
/// and phase leave out the points with coherence below kFrfMinCoherence (said in the title).
io::Figure FrfFigure(const Traces::Record& t, std::size_t first);

/// Share of the residual energy against share of the samples in each state condition, as bars
/// (one panel per diagnosed channel); a condition marked "*" holds in too many (or no) samples to
/// localise anything (said in the panel's title). No panels if there are no conditions.
io::Figure ConditionFigure(const Result& r);

/// Measured and predicted channel and the residuals over the 2 s window with the largest
/// nominal residual energy.
io::Figure TraceFigure(const Traces::Record& t, const std::string& channel);

}  // namespace rths::diagnosis
