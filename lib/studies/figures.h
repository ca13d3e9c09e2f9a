#pragma once
/// @file The reproductions' figures: one style for each controller in every figure.
///
/// Rules (io/plot.h): units of docs/units.md (displacement mm, force kN, velocity mm/s,
/// acceleration mm/s^2, frequency Hz, time s, time lag ms); colours from io::ReadableColors(),
/// none paler than io::kMaxReadableLuminance; legends beside the axes or where no data is; the
/// proposed controller of a figure drawn thickest.
#include <string>

#include "io/plot.h"

namespace rths::studies {

/// How a controller's curve is drawn.
struct CurveStyle {
  std::string color;      ///< "#rrggbb"
  int dash = 1;           ///< gnuplot dashtype
  double width = 1.5;     ///< line width
  int point_type = 7;     ///< gnuplot point type for "linespoints"
  double point_size = 1.0;
};

/// The style of a controller by its Table 1 name, the same in Figs. 7-9 and 11: None grey,
/// 3rd Poly vermillion, Lead Comp reddish purple, Bumpless wine, G_FF + LP bluish green, G_FF
/// blue, G_FF + LQG black, Numerical (Fig. 11's reference) grey dashed; any other name takes
/// io::ReadableColors()[index % size]. `prominent` (the figure's proposed controller) makes the
/// line twice as wide and its points larger.
CurveStyle ControllerStyle(const std::string& name, bool prominent = false, std::size_t index = 0);

/// A series drawn `with` ("lines" or "linespoints") in `style`, titled `title`.
io::Series StyledSeries(const std::string& title, const CurveStyle& style, const std::string& with = "lines");

}  // namespace rths::studies
