#pragma once
/// @file A small gnuplot wrapper for the reproductions' figures.
///
/// Plot(figure, dir) writes three files into dir and runs gnuplot (terminal pngcairo):
///   <name>.dat  the data, whitespace-separated columns "x y", one block per curve (gnuplot
///               `index`), each block preceded by a comment naming its panel, curve and units;
///   <name>.gp   the script, runnable again by hand: cd dir && gnuplot <name>.gp
///   <name>.png  the figure: one or more panels, stacked (Figs. 6-8) or side by side (Fig. 5).
/// Titles and labels are written literally (noenhanced), so "G_FF,0.0A + LP" stays as it is.
///
/// Figure conventions (every figure of rths): units as docs/units.md (mm, kN, s, Hz, mm/s,
/// mm/s^2) written "Quantity [unit]"; colours from ReadableColors() (also gnuplot's colour cycle for
/// a curve without a colour), none paler than kMaxReadableLuminance; a legend never over data
/// (Panel::key "outside ..." with Panel::right_margin_chars, or a corner the data leave empty).
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rths::io {

/// One curve.
struct Series {
  std::string title;            ///< legend entry; "" = no entry
  std::vector<double> x, y;     ///< same length; NaN/inf points are left out (the line breaks)
  std::string with = "lines";   ///< gnuplot style: "lines", "points", "linespoints", or "boxes"
                                ///< (filled bars from y = 0, Panel::box_width wide; MakeBarPanel)
  std::string color;            ///< "" = gnuplot's colour cycle; else a name or "#rrggbb"
  int dash = 1;                 ///< gnuplot dashtype: 1 solid, 2 dashed, 3 dotted, ...
  double width = 1.5;           ///< line width
};

/// One set of axes.
struct Panel {
  std::string title;                               ///< "" = none
  std::string xlabel, ylabel;                      ///< with units, e.g. "Frequency [Hz]"
  bool log_x = false, log_y = false;
  std::optional<std::pair<double, double>> x_range, y_range;  ///< unset = autoscale
  std::string key = "top right";                   ///< legend position (gnuplot `set key`), "off";
                                                   ///< "outside right top" puts it beside the axes
  std::vector<Series> series;
  /// Margins of the plot area in character widths (gnuplot `set lmargin` / `set rmargin`);
  /// -1 = automatic. Give stacked panels the same values and their axes line up; a key
  /// "outside right" needs right_margin_chars wide enough for its longest entry + ~8.
  int left_margin_chars = -1, right_margin_chars = -1;
  /// Labelled x ticks (x, label), e.g. categories of a bar chart; empty = numeric ticks.
  std::vector<std::pair<double, std::string>> x_tics;
  /// Numeric x ticks (x_tics empty, linear axis): at most this many, at a step of 1, 2 or 5 x 10^k
  /// over the curves' x span, so that long tick labels on a narrow panel do not run into each
  /// other; 0 = gnuplot's choice.
  int max_x_tics = 0;
  bool rotate_x_tics = false;                      ///< x tick labels slanted (long category names)
  double box_width = 0.8;                          ///< width of "boxes" bars [x units]
  /// An x interval [x units] shaded light grey behind the data over the panel's height (a fitted
  /// band, say); unset = none.
  std::optional<std::pair<double, double>> shade_x;
  /// Space left between the data and the frame, as a fraction of the plot area on every side of
  /// an autoscaled axis (gnuplot `set offsets graph f, ...`): points at the data's extremes stay
  /// off the frame. 0 = none (gnuplot's autoscale, extremes on the frame when they fall on a tic).
  double margin_fraction = 0.0;
  /// The same above and below only (a time history keeps its ends on the frame, its peaks off
  /// it); the larger of the two applies to y.
  double y_margin_fraction = 0.0;
};

struct Figure {
  std::string name;             ///< file stem: letters, digits, '_', '-', '.'
  std::string title;            ///< over all panels ("" = none)
  std::vector<Panel> panels;
  int columns = 1;              ///< panels per row (1: stacked, as in Figs. 6-8)
  int width_px = 1000;          ///< whole figure (about 6.7 in at 150 dpi)
  int panel_height_px = 330;    ///< per row of panels
  std::string font = "sans,11";
  std::string gnuplot = "gnuplot";  ///< program to run: a path, or a name in /usr/local/bin, /usr/bin, /bin
};

/// A panel with its title and axis labels (the rest default).
inline Panel MakePanel(std::string title, std::string xlabel, std::string ylabel) {
  Panel p;
  p.title = std::move(title);
  p.xlabel = std::move(xlabel);
  p.ylabel = std::move(ylabel);
  return p;
}
/// A curve with its legend entry and, optionally, colour and dash type.
inline Series MakeSeries(std::string title, std::string color = "", int dash = 1) {
  Series s;
  s.title = std::move(title);
  s.color = std::move(color);
  s.dash = dash;
  return s;
}

/// Bars over named categories: category i at x = i + 1, series j of n offset so the n bars of a
/// category sit side by side (together 0.8 wide). Each series gives its title, colour and one y
/// per category (y.size() == categories.size(), else rths::Error); its x and `with` are set here.
/// The x ticks are the category names.
Panel MakeBarPanel(std::string title, std::string ylabel, const std::vector<std::string>& categories,
                   std::vector<Series> series);

/// Okabe & Ito's colour-blind-safe palette (2008) without the three of its colours that are too
/// pale on white (orange, sky blue, yellow), in order: blue #0072B2, vermillion #D55E00, bluish
/// green #009E73, reddish purple #CC79A7, black #000000; then Tol's wine #882255 and a grey
/// #666666. gnuplot's colour cycle in every figure (curves without a colour).
const std::vector<std::string>& ReadableColors();

/// Relative luminance (WCAG 2.1) of a "#rrggbb" colour, in [0, 1] (black 0, white 1). Throws
/// rths::Error for anything else (names like "red" included).
double RelativeLuminance(const std::string& hex_color);

/// The palest a curve may be on the white background: luminance 0.30 is a contrast of 3:1 with
/// white ((1 + 0.05) / (0.30 + 0.05)), WCAG 2.1's minimum for graphical objects.
inline constexpr double kMaxReadableLuminance = 0.30;

/// The right margin [characters] a key "outside right" needs for the legend entries of `panels`:
/// the longest title + 10, at least 12. (gnuplot draws the box as wide as the title + about 7
/// characters for the sample line, padding and Plot's `width 1`, ~1 character from the figure's
/// edge; the rest is the gap to the axes. Measured with sans 11 on pngcairo.)
int KeyMarginChars(const std::vector<const Panel*>& panels);

/// The tick step for at most `max_tics` ticks over [lo, hi]: the smallest 1, 2 or 5 x 10^k with
/// (hi - lo) / step <= max_tics - 1; 0 for an empty or non-finite span or max_tics < 2.
double NiceTicStep(double lo, double hi, int max_tics);

struct PlotFiles {
  std::filesystem::path dat, gp, png;
};

/// Writes dir/<name>.dat and dir/<name>.gp and runs gnuplot to make dir/<name>.png. Throws
/// rths::Error if the figure is malformed (bad name, x/y lengths differ, a panel without any
/// finite point), if gnuplot is not installed ("install gnuplot: apt-get install gnuplot-nox"),
/// or if gnuplot fails (with its messages) or leaves no PNG.
PlotFiles Plot(const Figure& figure, const std::filesystem::path& dir);

/// Draws `figure` with Plot in a private temporary folder and puts only its PNG at `png` (for a
/// user who asked for a picture, not gnuplot's data and script). Throws what Plot throws, or
/// rths::Error naming `png` if it cannot be written.
void PlotPng(Figure figure, const std::filesystem::path& png);

/// True if `program` can be run (an executable path, or a name found in /usr/local/bin, /usr/bin
/// or /bin; a main program looks the user's PATH up itself: tools/cli.h ProgramOnPath).
bool GnuplotAvailable(const std::string& program = "gnuplot");

/// A string as a gnuplot single-quoted literal ('' for a quote inside).
std::string GnuplotQuote(const std::string& s);

}  // namespace rths::io
