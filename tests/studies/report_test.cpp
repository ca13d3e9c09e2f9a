// lib/io: RFC 4180 CSV writing and parsing, and the gnuplot wrapper (a real PNG, a script
// with the labels and legend entries, clear errors).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/csv.h"
#include "io/plot.h"
#include "studies/fig11.h"
#include "studies/fig9.h"
#include "studies/figures.h"
#include "test_support.h"

using namespace rths::io;
using rths_test::TempDir;
using rths_test::Slurp;

TEST_CASE("CSV fields are quoted exactly when RFC 4180 requires it") {
  CHECK(CsvField("None") == "None");
  CHECK(CsvField("3rd Poly 8ms") == "3rd Poly 8ms");
  CHECK(CsvField("") == "");
  CHECK(CsvField("G_FF,0.0A + LP") == "\"G_FF,0.0A + LP\"");
  CHECK(CsvField("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(CsvField("two\nlines") == "\"two\nlines\"");
  CHECK(CsvField("cr\rhere") == "\"cr\rhere\"");
  CHECK(CsvField("\"") == "\"\"\"\"");
  CHECK(CsvRecord({"a", "b,c", "d"}) == "a,\"b,c\",d\r\n");
  CHECK(CsvRecord({""}) == "\r\n");
}

TEST_CASE("CSV round trip and parse errors") {
  const std::vector<std::vector<std::string>> table{
      {"condition", "controller", "band_hz"},
      {"0.0A", "G_FF,avgA + LQG", "0-15"},
      {"", " leading space", "quote \" inside"},
      {"multi\r\nline", ",", "\"\""}};
  std::string text;
  for (const auto& r : table) text += CsvRecord(r);
  CHECK(ParseCsv(text) == table);
  // LF line ends and no final line end are accepted too.
  CHECK(ParseCsv("a,b\nc,\"d,e\"") == std::vector<std::vector<std::string>>{{"a", "b"}, {"c", "d,e"}});
  CHECK_THROWS_AS(ParseCsv("a,\"unterminated\r\n"), rths::Error);
  CHECK_THROWS_AS(ParseCsv("a,b\"c\r\n"), rths::Error);
  CHECK_THROWS_AS(ParseCsv("\"a\"b,c\r\n"), rths::Error);

  const auto dir = TempDir("csv");
  {
    CsvWriter w(dir / "t.csv", {"x", "name"});
    w.Row({"1", "G_FF,2.5A + LP"});
    CHECK_THROWS_AS(w.Row({"only one"}), rths::Error);
    w.Close();
  }
  CHECK(Slurp(dir / "t.csv") == "x,name\r\n1,\"G_FF,2.5A + LP\"\r\n");
  CHECK(ReadCsvFile(dir / "t.csv")[1][1] == "G_FF,2.5A + LP");
  CHECK_THROWS_AS(CsvWriter(dir / "no" / "such" / "folder.csv", {"a"}), rths::Error);
  CHECK(FormatSig(46.4371, 4) == "46.44");
  CHECK(FormatSig(0.071234, 3) == "0.0712");
  CHECK(FormatSig(std::nan(""), 3) == "nan");
}

TEST_CASE("a plot makes a PNG, and its script carries the labels, legend and options") {
  const auto dir = TempDir("plot");
  Figure fig;
  fig.name = "bode";
  fig.title = "G_yr at 0.0 A";
  Panel mag = MakePanel("", "Frequency [Hz]", "Magnitude [-]");
  mag.log_y = true;
  Panel lag = MakePanel("", "Frequency [Hz]", "Time lag [ms]");
  lag.x_range = std::make_pair(0.0, 50.0);
  lag.shade_x = std::make_pair(0.5, 40.0);  // a fitted band
  Series a = MakeSeries("G_FF,0.0A + LP"), b = MakeSeries("it's dashed", "black", 2);
  for (int i = 1; i <= 50; ++i) {
    a.x.push_back(i);
    a.y.push_back(1.0 + 0.01 * i);
    b.x.push_back(i);
    b.y.push_back(i == 25 ? std::numeric_limits<double>::quiet_NaN() : 1.0 / i);
  }
  mag.series = {a, b};
  lag.series = {a};
  fig.panels = {mag, lag};

  const PlotFiles files = Plot(fig, dir);
  const std::string png = Slurp(files.png);
  REQUIRE(png.size() > 1000);
  CHECK(png.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));

  const std::string gp = Slurp(files.gp);
  CHECK(gp.find("set terminal pngcairo") != std::string::npos);
  CHECK(gp.find("set multiplot layout 2,1") != std::string::npos);
  CHECK(gp.find("set xlabel 'Frequency [Hz]'") != std::string::npos);
  CHECK(gp.find("set ylabel 'Magnitude [-]'") != std::string::npos);
  CHECK(gp.find("set ylabel 'Time lag [ms]'") != std::string::npos);
  CHECK(gp.find("title 'G_FF,0.0A + LP'") != std::string::npos);
  CHECK(gp.find("title 'it''s dashed'") != std::string::npos);  // gnuplot's quote doubling
  CHECK(gp.find("set logscale y") != std::string::npos);
  CHECK(gp.find("set xrange [0:50]") != std::string::npos);
  CHECK(gp.find("dt 2 lc rgb 'black'") != std::string::npos);
  // The shaded band: on the second panel only, behind the curves; the first panel clears it.
  const auto shade = gp.find("set object 1 rect from 0.5,graph 0 to 40,graph 1 behind");
  REQUIRE(shade != std::string::npos);
  CHECK(gp.find("set object 1 rect", shade + 1) == std::string::npos);
  CHECK(gp.find("# panel 2") < shade);
  CHECK(gp.find("unset object 1") < gp.find("# panel 2"));

  // The data: three curves, whitespace-separated columns, the NaN point left out.
  const std::string dat = Slurp(files.dat);
  CHECK(dat.find("# index 2:") != std::string::npos);
  CHECK(dat.find("# index 3:") == std::string::npos);
  CHECK(dat.find("nan") == std::string::npos);
  CHECK(dat.find("\n50 1.5\n") != std::string::npos);
}

TEST_CASE("plot errors are clear") {
  const auto dir = TempDir("plot_errors");
  Figure fig;
  fig.name = "f";
  Panel p = MakePanel("", "x [s]", "y [mm]");
  Series s = MakeSeries("s");
  s.x = {0, 1, 2};
  s.y = {0, 1};
  p.series = {s};
  fig.panels = {p};
  CHECK_THROWS_WITH_AS(Plot(fig, dir), doctest::Contains("3 x values but 2 y values"), rths::Error);

  fig.panels[0].series[0].y = {NAN, NAN, NAN};
  CHECK_THROWS_WITH_AS(Plot(fig, dir), doctest::Contains("no finite point"), rths::Error);

  fig.panels[0].series[0].y = {0, 1, 2};
  fig.gnuplot = "rths-no-such-gnuplot";
  CHECK_FALSE(GnuplotAvailable(fig.gnuplot));
  CHECK_THROWS_WITH_AS(Plot(fig, dir), doctest::Contains("gnuplot is not installed"), rths::Error);

  fig.gnuplot = "gnuplot";
  fig.name = "bad name";
  CHECK_THROWS_AS(Plot(fig, dir), rths::Error);
}

TEST_CASE("a gnuplot killed by Ctrl-C is an interrupt (exit 130 in the tools), not a failed figure") {
  // Ctrl-C reaches the whole foreground group: gnuplot dies of SIGINT while a study plots. A
  // stand-in gnuplot that does the same; one that fails (exit 1) stays a plot error.
  const auto dir = TempDir("plot_interrupted");
  const auto write_script = [&](const std::string& name, const std::string& body) {
    const auto path = dir / name;
    std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
    std::filesystem::permissions(path, std::filesystem::perms::owner_all);
    return path.string();
  };
  Figure fig;
  fig.name = "f";
  Panel p = MakePanel("", "x [s]", "y [mm]");
  Series s = MakeSeries("s");
  s.x = {0, 1, 2};
  s.y = {0, 1, 2};
  p.series = {s};
  fig.panels = {p};
  fig.gnuplot = write_script("gnuplot-sigint", "kill -INT $$");
  CHECK_THROWS_WITH_AS(Plot(fig, dir), doctest::Contains("interrupted (signal 2)"), rths::Interrupted);
  fig.gnuplot = write_script("gnuplot-sigterm", "kill -TERM $$");
  CHECK_THROWS_AS(Plot(fig, dir), rths::Interrupted);
  fig.gnuplot = write_script("gnuplot-fails", "echo broken >&2; exit 1");
  try {
    Plot(fig, dir);
    FAIL("no throw");
  } catch (const rths::Interrupted&) {
    FAIL("a failed gnuplot is not an interrupt");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("gnuplot failed (exit 1)") != std::string::npos);
  }
}

// --- Figure conventions (io/plot.h, studies/figures.h) ------------------------------------

namespace {
// Every "[unit]" of the axis labels of a figure.
std::vector<std::string> Units(const Figure& fig) {
  std::vector<std::string> units;
  for (const auto& p : fig.panels) {
    for (const std::string& label : {p.xlabel, p.ylabel}) {
      const auto a = label.rfind('['), b = label.rfind(']');
      if (a != std::string::npos && b != std::string::npos && b > a) units.push_back(label.substr(a + 1, b - a - 1));
    }
  }
  return units;
}
const std::set<std::string> kFigureUnits{"mm", "kN", "s", "ms", "Hz", "mm/s", "mm/s^2", "%", "deg", "mm/mm", "-"};
}  // namespace

TEST_CASE("the readable palette: distinct #rrggbb colours, none paler than 3:1 against white") {
  CHECK(RelativeLuminance("#000000") == 0.0);
  CHECK(RelativeLuminance("#FFFFFF") == doctest::Approx(1.0));
  CHECK(RelativeLuminance("#f0e442") > kMaxReadableLuminance);  // Okabe-Ito yellow: too pale
  CHECK(RelativeLuminance("#56B4E9") > kMaxReadableLuminance);  // Okabe-Ito sky blue: too pale
  CHECK_THROWS_AS(RelativeLuminance("red"), rths::Error);
  CHECK_THROWS_AS(RelativeLuminance("#12345g"), rths::Error);
  const auto& colors = ReadableColors();
  CHECK(colors.size() >= 6);
  CHECK(std::set<std::string>(colors.begin(), colors.end()).size() == colors.size());
  for (const auto& c : colors) {
    CAPTURE(c);
    CHECK(RelativeLuminance(c) <= kMaxReadableLuminance);
  }
}

TEST_CASE("a plot's colour cycle is the readable palette; margins and a legend beside the axes reach the script") {
  const auto dir = TempDir("plot_cycle");
  Figure fig;
  fig.name = "cycle";
  Panel p = MakePanel("", "Time [s]", "Displacement [mm]");
  p.key = "outside right top";
  p.left_margin_chars = 10;
  p.right_margin_chars = 30;
  Series s = MakeSeries("a");
  s.x = {0, 1};
  s.y = {0, 1};
  p.series = {s};
  fig.panels = {p};
  CHECK(KeyMarginChars({&p}) == 12);  // the shortest entries still get a sample line and a box
  Panel wide = p;
  wide.series[0].title = std::string(40, 'w');
  CHECK(KeyMarginChars({&p, &wide}) == 50);
  const std::string gp = Slurp(Plot(fig, dir).gp);
  CHECK(gp.find("set linetype 1 lc rgb '" + ReadableColors()[0] + "'") != std::string::npos);
  CHECK(gp.find("set linetype cycle " + std::to_string(ReadableColors().size())) != std::string::npos);
  CHECK(gp.find("set key on outside right top box opaque spacing 1.2 width 1") != std::string::npos);
  CHECK(gp.find("set lmargin 10") != std::string::npos);
  CHECK(gp.find("set rmargin 30") != std::string::npos);
}

TEST_CASE("a run of non-finite points breaks a curve once and never ends its data block") {
  const auto dir = TempDir("plot_gaps");
  Figure fig;
  fig.name = "gaps";
  Panel p = MakePanel("", "Frequency [Hz]", "Magnitude [mm/mm]");
  Series a = MakeSeries("masked"), b = MakeSeries("after");
  a.x = {1, 2, 3, 4, 5};
  a.y = {1, NAN, NAN, NAN, 2};
  b.x = {1, 2};
  b.y = {7, 8};
  p.series = {a, b};
  fig.panels = {p};
  const std::string dat = Slurp(Plot(fig, dir).dat);
  CHECK(dat.find("\n1 1\n\n5 2\n") != std::string::npos);  // one blank line: the curve breaks
  std::size_t blocks = 0;
  for (auto at = dat.find("\n\n\n"); at != std::string::npos; at = dat.find("\n\n\n", at + 1)) ++blocks;
  CHECK(blocks == 1);  // two blank lines only between the two curves: `index 1` is "after"
  CHECK(dat.find("2\n\n\n# index 1") != std::string::npos);
}

TEST_CASE("a bar panel: filled boxes side by side over named categories") {
  Series a = MakeSeries("share of the residual", "#D55E00"), b = MakeSeries("share of the samples", "#0072B2");
  a.y = {30, 50, 20};
  b.y = {10, 15, 88};
  const Panel p = MakeBarPanel("conditions", "Share [%]", {"velocity_reversal", "high_velocity", "high_force"}, {a, b});
  REQUIRE(p.series.size() == 2);
  CHECK(p.series[0].with == "boxes");
  CHECK(p.x_tics.size() == 3);
  CHECK(p.x_tics[1] == std::make_pair(2.0, std::string("high_velocity")));
  CHECK(p.box_width == doctest::Approx(0.4));
  // The two bars of a category side by side around it, not overlapping.
  CHECK(p.series[0].x[1] == doctest::Approx(1.8));
  CHECK(p.series[1].x[1] == doctest::Approx(2.2));
  CHECK(p.x_range == std::make_optional(std::make_pair(0.5, 3.5)));
  b.y.pop_back();
  CHECK_THROWS_WITH_AS(MakeBarPanel("c", "[%]", {"a", "b", "c"}, {a, b}), doctest::Contains("2 values for 3 categories"),
                       rths::Error);

  const auto dir = TempDir("plot_bars");
  Figure fig;
  fig.name = "bars";
  fig.panels = {p};
  const std::string gp = Slurp(Plot(fig, dir).gp);
  CHECK(gp.find("with boxes") != std::string::npos);
  CHECK(gp.find("set xtics ('velocity_reversal' 1, 'high_velocity' 2, 'high_force' 3)") != std::string::npos);
  CHECK(gp.find("set boxwidth 0.4 absolute") != std::string::npos);
}

TEST_CASE("fig9's figure: every controller a distinct readable colour, the proposed G_FF,0.0A the most prominent") {
  rths::studies::Fig9Result res;
  double v = 0.1;
  for (double f : rths::studies::Fig9FrequenciesHz()) {
    for (const auto& c : rths::studies::Fig9Controllers()) {
      rths::studies::Fig9Row row;
      row.f_hz = f;
      row.controller = c.name;
      row.rms_pct = v *= 1.1;
      if (f == 30.0 && c.name == "None") row.stopped = "stroke limit";
      res.rows.push_back(row);
    }
  }
  const Figure fig = rths::studies::Fig9Figure(res, "physical", true);
  REQUIRE(fig.panels.size() == 1);
  const Panel& p = fig.panels[0];
  std::set<std::string> colors;
  double widest_other = 0.0, proposed = 0.0;
  std::size_t curves = 0;
  for (const auto& s : p.series) {
    if (s.title == "stopped by the safety monitor") continue;
    ++curves;
    CAPTURE(s.title);
    CAPTURE(s.color);
    REQUIRE(s.color.size() == 7);
    CHECK(RelativeLuminance(s.color) <= kMaxReadableLuminance);
    colors.insert(s.color);
    CHECK(s.x.size() == 6);
    if (s.title == "G_FF,0.0A") {
      proposed = s.width;
    } else {
      widest_other = std::max(widest_other, s.width);
    }
  }
  CHECK(curves == 6);
  CHECK(colors.size() == 6);
  CHECK(proposed > widest_other);
  CHECK(p.series.back().title == "stopped by the safety monitor");
  CHECK(p.series.back().x == std::vector<double>{30.0});
  CHECK(p.key.rfind("outside", 0) == 0);
  for (const auto& u : Units(fig)) CHECK(kFigureUnits.count(u) == 1);
}

TEST_CASE("fig11's stories figure: one legend beside the axes, accelerations in mm/s^2 like the logs") {
  rths::studies::Fig11Result res;
  for (const auto& mode : rths::studies::Fig11SemiactiveModes()) {
    rths::studies::Fig11Run n;
    n.controller = "Numerical";
    n.semiactive = mode;
    for (int i = 0; i < 9; ++i) {
      n.peak_drift_mm.push_back(10.0 + i);
      n.peak_abs_accel_mps2.push_back(1.5 + 0.1 * i);
    }
    res.numerical.push_back(n);
    for (const auto& c : rths::studies::Fig11Controllers()) {
      rths::studies::Fig11Run r = n;
      r.controller = c.name;
      res.runs.push_back(r);
    }
  }
  const Figure fig = rths::studies::Fig11StoriesFigure(res);
  REQUIRE(fig.panels.size() == 2);
  const Panel& drift = fig.panels[0];
  const Panel& acc = fig.panels[1];
  // The curves cover the story-1 corner of both panels: the legend goes beside the right one.
  CHECK(drift.key == "off");
  CHECK(acc.key.rfind("outside right", 0) == 0);
  CHECK(acc.right_margin_chars == KeyMarginChars({&acc}));  // room for the legend's longest entry
  REQUIRE(acc.series.size() == 6);  // 3 modes x (numerical, RTHS with G_FF,avgA + LQG)
  CHECK(fig.title.find("G_FF,avgA + LQG") != std::string::npos);
  CHECK(acc.xlabel == "Peak acceleration [mm/s^2]");
  CHECK(acc.series[0].x[0] == doctest::Approx(1500.0));
  CHECK(acc.series[0].x[8] == doctest::Approx(2300.0));
  for (const auto& u : Units(fig)) CHECK(kFigureUnits.count(u) == 1);
  for (const auto& s : acc.series) CHECK(RelativeLuminance(s.color) <= kMaxReadableLuminance);
}
