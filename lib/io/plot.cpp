#include "io/plot.h"

#include <unistd.h>

#include <csignal>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"
#include "core/interrupt.h"
#include "io/command.h"

namespace rths::io {

namespace fs = std::filesystem;

namespace {

bool ValidName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

std::string Num(double v) { return fmt::format("{:.10g}", v); }

}  // namespace

std::string GnuplotQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += '\'';
    if (c == '\n') {
      out += "\\n";  // only meaningful in double quotes; keep labels on one line
      continue;
    }
    out += c;
  }
  out += '\'';
  return out;
}

const std::vector<std::string>& ReadableColors() {
  static const std::vector<std::string> colors{"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                               "#000000", "#882255", "#666666"};
  return colors;
}

double RelativeLuminance(const std::string& hex_color) {
  auto hex = [&](std::size_t i) {
    const char c = hex_color[i];
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  bool ok = hex_color.size() == 7 && hex_color[0] == '#';
  for (std::size_t i = 1; ok && i < 7; ++i) ok = hex(i) >= 0;
  if (!ok) throw Error("RelativeLuminance", fmt::format("colour '{}' is not of the form #rrggbb", hex_color));
  auto linear = [&](std::size_t i) {  // sRGB channel -> linear light
    const double c = (16 * hex(i) + hex(i + 1)) / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  return 0.2126 * linear(1) + 0.7152 * linear(3) + 0.0722 * linear(5);
}

Panel MakeBarPanel(std::string title, std::string ylabel, const std::vector<std::string>& categories,
                   std::vector<Series> series) {
  Panel p = MakePanel(std::move(title), "", std::move(ylabel));
  const double n = static_cast<double>(std::max<std::size_t>(series.size(), 1));
  p.box_width = 0.8 / n;
  for (std::size_t j = 0; j < series.size(); ++j) {
    Series& s = series[j];
    if (s.y.size() != categories.size()) {
      throw Error("MakeBarPanel", fmt::format("series '{}' has {} values for {} categories", s.title, s.y.size(),
                                              categories.size()));
    }
    s.with = "boxes";
    s.x.clear();
    const double offset = (static_cast<double>(j) - 0.5 * (n - 1.0)) * p.box_width;
    for (std::size_t i = 0; i < categories.size(); ++i) s.x.push_back(static_cast<double>(i + 1) + offset);
  }
  for (std::size_t i = 0; i < categories.size(); ++i) p.x_tics.emplace_back(static_cast<double>(i + 1), categories[i]);
  p.x_range = std::make_pair(0.5, static_cast<double>(categories.size()) + 0.5);
  p.series = std::move(series);
  return p;
}

int KeyMarginChars(const std::vector<const Panel*>& panels) {
  std::size_t longest = 2;
  for (const Panel* p : panels) {
    for (const auto& s : p->series) longest = std::max(longest, s.title.size());
  }
  return std::max(12, static_cast<int>(longest) + 10);
}

double NiceTicStep(double lo, double hi, int max_tics) {
  const double span = hi - lo;
  if (!std::isfinite(span) || span <= 0 || max_tics < 2) return 0.0;
  const double least = span / (max_tics - 1);
  double decade = std::pow(10.0, std::floor(std::log10(least)));
  for (;;) {
    for (const double m : {1.0, 2.0, 5.0}) {
      if (m * decade >= least * (1 - 1e-12)) return m * decade;
    }
    decade *= 10;
  }
}

bool GnuplotAvailable(const std::string& program) { return !FindProgram(program).empty(); }

namespace {

/// Writes the data file: one block per curve with at least one finite point. Returns, per panel,
/// each curve's block (-1: none). Throws rths::Error on a malformed figure.
std::vector<std::vector<int>> WriteData(const Figure& fig, const fs::path& file, const std::string& where) {
  std::ofstream dat(file);
  if (!dat) throw Error(file.string(), "cannot open for writing");
  dat << "# " << fig.name << ": data of " << fig.name << ".png (whitespace-separated columns; "
      << "one block per curve, blocks separated by two blank lines: gnuplot `index`)\n";
  std::vector<std::vector<int>> index(fig.panels.size());
  int next_index = 0;
  for (std::size_t p = 0; p < fig.panels.size(); ++p) {
    const Panel& panel = fig.panels[p];
    for (std::size_t s = 0; s < panel.series.size(); ++s) {
      const Series& ser = panel.series[s];
      if (ser.x.size() != ser.y.size()) {
        throw Error(where, fmt::format("panel {} curve '{}': {} x values but {} y values", p + 1,
                                       ser.title, ser.x.size(), ser.y.size()));
      }
      bool any = false;
      for (std::size_t i = 0; i < ser.x.size(); ++i) {
        any = any || (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i]));
      }
      if (!any) {
        index[p].push_back(-1);
        continue;
      }
      if (next_index > 0) dat << "\n\n";
      dat << fmt::format("# index {}: panel {} curve \"{}\"\n# x: {}   y: {}\n", next_index, p + 1,
                         ser.title, panel.xlabel, panel.ylabel);
      // One blank line breaks the curve at a run of non-finite points; never two in a row (two
      // blank lines end the block for gnuplot's `index`, shifting every later curve).
      bool written = false, gap = false;
      for (std::size_t i = 0; i < ser.x.size(); ++i) {
        if (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i])) {
          if (gap && written) dat << '\n';
          dat << Num(ser.x[i]) << ' ' << Num(ser.y[i]) << '\n';
          written = true;
          gap = false;
        } else {
          gap = true;
        }
      }
      index[p].push_back(next_index++);
    }
    bool has = false;
    for (int i : index[p]) has = has || i >= 0;
    if (!has) throw Error(where, fmt::format("panel {} ('{}') has no finite point to plot", p + 1, panel.ylabel));
  }
  dat.close();
  if (!dat) throw Error(file.string(), "write failed");
  return index;
}

/// Panel p's part of the script: axes, ranges, tics, key and its curves (`blocks`: each curve's
/// data block, -1 for a curve without a finite point).
void WritePanel(std::ostringstream& gp, const Panel& panel, std::size_t p, const std::vector<int>& blocks,
                const std::string& dat_name) {
  gp << "\n# panel " << p + 1 << "\n"
     << "unset logscale\nset grid\nset autoscale\n"
     << "set title " << GnuplotQuote(panel.title) << "\n"
     << "set xlabel " << GnuplotQuote(panel.xlabel) << "\n"
     << "set ylabel " << GnuplotQuote(panel.ylabel) << "\n";
  if (panel.log_x) gp << "set logscale x\n";
  if (panel.log_y) gp << "set logscale y\n";
  // Log axes: plain tick labels (1e-06, 0.001, 100), not gnuplot's fixed "0.0000010".
  gp << "set format x " << (panel.log_x ? "'%g'" : "'% h'") << "\nset format y " << (panel.log_y ? "'%g'" : "'% h'")
     << "\n";
  gp << (panel.x_range ? fmt::format("set xrange [{}:{}]\n", Num(panel.x_range->first), Num(panel.x_range->second))
                       : std::string("set xrange [*:*]\n"));
  gp << (panel.y_range ? fmt::format("set yrange [{}:{}]\n", Num(panel.y_range->first), Num(panel.y_range->second))
                       : std::string("set yrange [*:*]\n"));
  gp << fmt::format("set lmargin {}\nset rmargin {}\n", panel.left_margin_chars < 0 ? -1 : panel.left_margin_chars,
                    panel.right_margin_chars < 0 ? -1 : panel.right_margin_chars);
  if (panel.x_tics.empty()) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Series& ser : panel.series) {
      for (const double x : ser.x) {
        if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
      }
    }
    const double step = panel.log_x ? 0.0 : NiceTicStep(lo, hi, panel.max_x_tics);
    // With a fixed step, the range stays the data's (plus the offsets), not widened to a tick.
    gp << (step > 0 ? fmt::format("set xtics {}\nset autoscale xfix\n", Num(step)) : std::string("set xtics autofreq\n"));
  } else {
    gp << "set xtics (";
    for (std::size_t i = 0; i < panel.x_tics.size(); ++i) {
      gp << (i ? ", " : "") << GnuplotQuote(panel.x_tics[i].second) << " " << Num(panel.x_tics[i].first);
    }
    gp << ")\n";
  }
  gp << (panel.rotate_x_tics ? "set xtics rotate by -25\n" : "set xtics norotate\n");
  gp << fmt::format("set boxwidth {} absolute\nset style fill solid 0.85 border -1\n", Num(panel.box_width));
  if (panel.margin_fraction > 0 || panel.y_margin_fraction > 0) {
    const std::string fx = Num(panel.margin_fraction);
    const std::string fy = Num(std::max(panel.margin_fraction, panel.y_margin_fraction));
    gp << fmt::format("set offsets graph {0}, graph {0}, graph {1}, graph {1}\n", fx, fy);
  } else {
    gp << "unset offsets\n";
  }
  gp << "unset object 1\n";
  if (panel.shade_x) {
    gp << fmt::format("set object 1 rect from {},graph 0 to {},graph 1 behind fc rgb '#ebebeb' fs solid 1.0 noborder\n",
                      Num(panel.shade_x->first), Num(panel.shade_x->second));
  }
  gp << "set key default\n";  // nothing of the previous panel's key (outside, width) carries over
  if (panel.key == "off") {
    gp << "set key off\n";
  } else {
    gp << "set key on " << panel.key << " box opaque spacing 1.2";
    // Beside the axes: one character more than gnuplot's estimate of the titles, whose capitals
    // run wider ("G_FF,avgA + LQG" would start left of its box).
    if (panel.key.find("outside") != std::string::npos && panel.key.find("width") == std::string::npos) gp << " width 1";
    gp << "\n";
  }
  gp << "plot ";
  bool first = true;
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    if (blocks[s] < 0) continue;
    const Series& ser = panel.series[s];
    if (!first) gp << ", \\\n     ";
    first = false;
    gp << dat_name << " index " << blocks[s] << " using 1:2 with " << ser.with;
    if (ser.with != "points") gp << " lw " << Num(ser.width) << " dt " << ser.dash;
    if (!ser.color.empty()) gp << " lc rgb " << GnuplotQuote(ser.color);
    gp << (ser.title.empty() ? std::string(" notitle") : " title " + GnuplotQuote(ser.title));
  }
  gp << "\n";
}

/// The gnuplot script of the figure (runnable again by hand), its curves read from `index`'s blocks.
std::string Script(const Figure& fig, const std::vector<std::vector<int>>& index) {
  const int rows = static_cast<int>((fig.panels.size() + fig.columns - 1) / fig.columns);
  const int height = rows * fig.panel_height_px + (fig.title.empty() ? 0 : 40);
  const std::string dat_name = GnuplotQuote(fig.name + ".dat");
  std::ostringstream gp;
  gp << "# " << fig.name << ".gp: written by rths (lib/report/plot.cpp). Run again with:\n"
     << "#   cd <this folder> && gnuplot " << fig.name << ".gp\n"
     << fmt::format("set terminal pngcairo noenhanced size {},{} font {}\n", fig.width_px, height,
                    GnuplotQuote(fig.font))
     << "set output " << GnuplotQuote(fig.name + ".png") << "\n"
     << "set encoding utf8\n";
  // The colour cycle of curves without a colour: readable on white, colour-blind safe.
  const auto& cycle = ReadableColors();
  for (std::size_t i = 0; i < cycle.size(); ++i) gp << fmt::format("set linetype {} lc rgb '{}'\n", i + 1, cycle[i]);
  gp << "set linetype cycle " << cycle.size() << "\n";
  if (fig.panels.size() > 1 || !fig.title.empty()) {
    gp << fmt::format("set multiplot layout {},{}", rows, fig.columns);
    if (!fig.title.empty()) gp << " title " << GnuplotQuote(fig.title);
    gp << "\n";
  }
  for (std::size_t p = 0; p < fig.panels.size(); ++p) WritePanel(gp, fig.panels[p], p, index[p], dat_name);
  if (fig.panels.size() > 1 || !fig.title.empty()) gp << "\nunset multiplot\n";
  gp << "set output\n";
  return gp.str();
}

}  // namespace

PlotFiles Plot(const Figure& fig, const fs::path& dir) {
  const std::string where = "plot " + fig.name;
  if (!ValidName(fig.name)) {
    throw Error(where, "figure name must be letters, digits, '_', '-' or '.'");
  }
  if (fig.panels.empty()) throw Error(where, "no panels");
  if (fig.columns < 1) throw Error(where, "columns must be >= 1");
  const std::string exe = FindProgram(fig.gnuplot);
  if (exe.empty()) {
    throw Error(where, fmt::format("gnuplot is not installed (no '{}' on PATH): install it with "
                                   "`apt-get install gnuplot-nox` (Debian) and run again",
                                   fig.gnuplot));
  }
  fs::create_directories(dir);
  PlotFiles files{dir / (fig.name + ".dat"), dir / (fig.name + ".gp"), dir / (fig.name + ".png")};

  const std::vector<std::vector<int>> index = WriteData(fig, files.dat, where);
  const std::string script = Script(fig, index);
  {
    std::ofstream out(files.gp);
    if (!out) throw Error(files.gp.string(), "cannot open for writing");
    out << script;
    if (!out) throw Error(files.gp.string(), "write failed");
  }

  std::error_code ec;
  fs::remove(files.png, ec);
  // An interrupt before the figure (Ctrl-C after the last run ended): no figure is drawn.
  if (InterruptRequested()) throw Interrupted(where, "interrupted before " + files.png.filename().string() + " was drawn");
  const CommandResult run = RunCommand({exe, fig.name + ".gp"}, dir);
  const int code = run.status;
  const std::string& output = run.output;
  if (code == 127) throw Error(where, fmt::format("cannot run {}: install gnuplot (apt-get install gnuplot-nox)", exe));
  // Ctrl-C reaches the whole foreground group: gnuplot killed by it, or (the real one) catching it
  // and exiting 1 while this process's handler recorded it. An interrupt, not a failure; the
  // half-drawn PNG goes.
  if (code == 128 + SIGINT || code == 128 + SIGTERM || (code != 0 && InterruptRequested())) {
    fs::remove(files.png, ec);
    throw Interrupted(where, code > 128 ? fmt::format("gnuplot was interrupted (signal {}) on {}", code - 128,
                                                      files.gp.string())
                                        : fmt::format("interrupted while gnuplot drew {}", files.png.string()));
  }
  if (code != 0) {
    throw Error(where, fmt::format("gnuplot failed (exit {}) on {}:\n{}", code, files.gp.string(), output));
  }
  if (!fs::exists(files.png) || fs::file_size(files.png) == 0) {
    throw Error(where, fmt::format("gnuplot made no PNG from {}:\n{}", files.gp.string(), output));
  }
  return files;
}

void PlotPng(Figure fig, const fs::path& png) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rths_plot_{}", ::getpid());
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  fig.name = "plot";
  try {
    const auto files = Plot(fig, dir);
    fs::copy_file(files.png, png, fs::copy_options::overwrite_existing, ec);
    if (ec) throw Error(png.string(), "cannot write the plot: " + ec.message());
  } catch (...) {
    fs::remove_all(dir, ec);
    throw;
  }
  fs::remove_all(dir, ec);
}

}  // namespace rths::io
