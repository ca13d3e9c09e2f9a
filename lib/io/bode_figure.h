#pragma once
/// @file The one Bode figure: magnitude, unwrapped phase, optionally time lag and
/// coherence, stacked against frequency, for any set of frequency responses (signal/bode.h). Drawn
/// by `rths identify` (measured H1 and the two fits, ident/actuator_fit.h), the frequency-domain
/// reproductions (Figs. 6-8, studies/frequency.h) and the run report (G_yr, report/run_figures.h);
/// what differs between them is the layout (BodeLayout) and each curve's style (BodeTrace).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/plot.h"
#include "signal/bode.h"

namespace rths::io {

/// One response and how it is drawn: `style`'s title, colour, dash and width (its x, y unused).
/// A NaN in the curve's magnitude or phase leaves that point out of its panel (a masked point).
struct BodeTrace {
  signal::BodeCurve curve;
  Series style;
  std::string phase_title;               ///< the phase panel's entry; "" = style.title
  std::optional<Series> coherence_style;  ///< draw its coherence in the coherence panel, so; unset = not
};

/// The panels and their axes.
struct BodeLayout {
  std::pair<double, double> f_range_hz{0.0, 50.0};  ///< every panel's frequency axis [Hz]
  std::string x_label = "Frequency [Hz]";
  std::string magnitude_title, magnitude_label = "Magnitude [mm/mm]";
  std::string phase_title, phase_label = "Phase [deg]";
  bool lag_panel = true;                            ///< time lag -phase / (2 pi f) [ms]
  std::string lag_title, lag_label = "Time lag [ms]";
  std::optional<std::pair<double, double>> lag_range_ms;  ///< unset = autoscale
  bool coherence_panel = false;                     ///< coherence [-] on 0-1.05
  std::string coherence_title, coherence_label = "Coherence γ² [-]";
  std::vector<Series> coherence_extra;              ///< drawn after the traces' coherence (a threshold)
  std::string magnitude_key = "outside right top";  ///< the one legend; the other panels' keys are off
  std::string coherence_key = "off";
  int left_margin_chars = -1;                       ///< every panel's (-1: automatic)
  bool key_margin = true;  ///< every panel's right margin that of the magnitude panel's key (axes aligned)
  std::optional<std::pair<double, double>> shade_hz;  ///< a band shaded in every panel [Hz]
};

/// The figure: panels magnitude, phase, then time lag and coherence if the layout asks, each
/// trace in each (coherence: those with a coherence_style), in the traces' order. The caller sets
/// the figure's name, title and size.
Figure BodeFigure(const BodeLayout& layout, const std::vector<BodeTrace>& traces);

}  // namespace rths::io
