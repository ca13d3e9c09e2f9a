#pragma once
/// @file The axes of a spectrum figure (the run report, the comparison, the diagnosis): the band that
/// carries the signal and a range of density a reader can see into, instead of every bin from the
/// first to Nyquist and every decade down to round-off.
#include <vector>

namespace rths::signal {

struct SpectrumAxes {
  double f_lo_hz = 0, f_hi_hz = 0;  ///< [Hz]
  double psd_lo = 0, psd_hi = 0;    ///< [unit^2/Hz]
};

/// `f` is the Welch grid [Hz] (f[0] = 0, uniform); `reference` the PSD of the signal that drives
/// the others (r); `curves` every PSD drawn (the reference included or not).
///   - x: from the first bin above DC to `widen` times the highest frequency at which the reference
///     is within `band_db` of its peak (at most the grid's last frequency);
///   - y: from the largest value of the curves over that band down `decades` decades (or to their
///     smallest positive value over it, if higher), widened by a factor 2 at both ends.
/// Requires f.size() >= 3 and every PSD of f's length (else the whole grid and autoscaled-like
/// bounds of the curves).
SpectrumAxes SpectrumAxesOf(const std::vector<double>& f, const std::vector<double>& reference,
                            const std::vector<const std::vector<double>*>& curves, double band_db = 40.0,
                            double widen = 1.5, double decades = 6.0);

}  // namespace rths::signal
