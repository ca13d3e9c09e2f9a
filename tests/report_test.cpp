// lib/io: RFC 4180 CSV writing and parsing, and the gnuplot wrapper (a real PNG, a script
// with the labels and legend entries, clear errors).
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/csv.h"
#include "io/plot.h"
#include "test_support.h"

using namespace rths::io;
using rths_test::TempDir;

namespace {
std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

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
