#pragma once
/// @file A small gnuplot wrapper for the reproductions' figures.
///
/// Plot(figure, dir) writes three files into dir and runs gnuplot (terminal pngcairo):
///   <name>.dat  the data, whitespace-separated columns "x y", one block per curve (gnuplot
///               `index`), each block preceded by a comment naming its panel, curve and units;
///   <name>.gp   the script, runnable again by hand: cd dir && gnuplot <name>.gp
///   <name>.png  the figure: one or more panels, stacked (Figs. 6-8) or side by side (Fig. 5).
/// Titles and labels are written literally (noenhanced), so "G_FF,0.0A + LP" stays as it is.
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
  std::string with = "lines";   ///< gnuplot style: "lines", "points", "linespoints"
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
  std::string key = "top right";                   ///< legend position (gnuplot `set key`), "off"
  std::vector<Series> series;
};

struct Figure {
  std::string name;             ///< file stem: letters, digits, '_', '-', '.'
  std::string title;            ///< over all panels ("" = none)
  std::vector<Panel> panels;
  int columns = 1;              ///< panels per row (1: stacked, as in Figs. 6-8)
  int width_px = 1000;          ///< whole figure (about 6.7 in at 150 dpi)
  int panel_height_px = 330;    ///< per row of panels
  std::string font = "sans,11";
  std::string gnuplot = "gnuplot";  ///< program to run (a name on PATH or a path)
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

struct PlotFiles {
  std::filesystem::path dat, gp, png;
};

/// Writes dir/<name>.dat and dir/<name>.gp and runs gnuplot to make dir/<name>.png. Throws
/// rths::Error if the figure is malformed (bad name, x/y lengths differ, a panel without any
/// finite point), if gnuplot is not installed ("install gnuplot: apt-get install gnuplot-nox"),
/// or if gnuplot fails (with its messages) or leaves no PNG.
PlotFiles Plot(const Figure& figure, const std::filesystem::path& dir);

/// True if `program` can be run (found on PATH, or an executable path).
bool GnuplotAvailable(const std::string& program = "gnuplot");

/// A string as a gnuplot single-quoted literal ('' for a quote inside).
std::string GnuplotQuote(const std::string& s);

}  // namespace rths::io
