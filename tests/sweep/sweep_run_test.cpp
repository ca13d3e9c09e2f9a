// The local executor of a sweep (lib/sweep/run_sweep.h, `rths sweep`): every run a row, the table
// in index order, a run re-made alone (--only) gives the same row bit for bit, --resume skips the
// rows already there, and a run whose drawn value is out of range is a row with its status.
#include <doctest/doctest.h>

#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/command.h"
#include "io/plot.h"
#include "scenario/scenario.h"
#include "sweep/run_sweep.h"
#include "sweep/table.h"
#include "plot_data.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

rths::sweep::Spec SmallSpec(const fs::path& dir, double sd) {
  const fs::path base = rths_test::WriteScenario(dir, "[run]\nname = \"sweep_base\"\nduration_s = 0.05\n");
  const fs::path spec = dir / "spec.toml";
  std::ofstream(spec) << "[sweep]\nname = \"small\"\nbase = \"" << base.string() << "\"\nseed = 3\ndraws = 2\n"
                      << "record = [\"tracking_nrmse_pct\", \"peak_force_kN\", \"steps\"]\n"
                      << "[grid]\n\"controller.kind\" = [\"none\", \"ff\"]\n"
                      << "[draw]\n\"structure.damping_ratio\" = { dist = \"normal\", mean = 0.02, std = " << sd
                      << " }\n";
  return rths::sweep::LoadSpec(spec.string());
}

}  // namespace

TEST_CASE("a small sweep: a row per run, the table, --only re-makes a run bit for bit, --resume skips") {
  const auto dir = rths_test::TempDir("sweep_run");
  const auto spec = SmallSpec(dir, 0.002);
  REQUIRE(spec.runs() == 4);
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  o.jobs = 2;
  const auto r = rths::sweep::RunSweep(spec, o);
  CHECK(r.ran == 4);
  CHECK(r.failed == 0);
  const std::string table = Read(r.table);
  CHECK(table.rfind("index,status,scenario_sha256,controller.kind,structure.damping_ratio,tracking_nrmse_pct,"
                    "peak_force_kN,steps\n",
                    0) == 0);
  int lines = 0;
  for (char c : table) lines += c == '\n';
  CHECK(lines == 5);
  const auto row2 = nlohmann::json::parse(Read(o.out / "rows" / "2.json"));
  CHECK(row2["status"] == "completed");
  CHECK(row2["set"]["controller.kind"] == "ff");
  CHECK(row2["record"]["steps"] == 100);
  CHECK(row2["record"]["tracking_nrmse_pct"].get<double>() > 0);
  CHECK_FALSE(fs::exists(o.out / "runs" / "2" / "log.lcm"));  // logs only when asked
  // Run 2 alone, in another folder: the same row, bit for bit.
  rths::sweep::SweepOptions alone = o;
  alone.out = dir / "alone";
  alone.only = 2;
  CHECK(rths::sweep::RunSweep(spec, alone).ran == 1);
  CHECK(nlohmann::json::parse(Read(alone.out / "rows" / "2.json")) == row2);
  // Resume: a lost row is made again; the others are skipped.
  fs::remove(o.out / "rows" / "1.json");
  rths::sweep::SweepOptions again = o;
  again.resume = true;
  const auto r2 = rths::sweep::RunSweep(spec, again);
  CHECK(r2.ran == 1);
  CHECK(r2.skipped == 3);
  CHECK(r2.kept == std::vector<std::int64_t>{0, 2, 3});  // the runs whose rows it kept (the tool prints them)
  CHECK(Read(r2.table) == table);
}

TEST_CASE("chunks (the tasks of a job array) into one folder make the table of the whole sweep") {
  const auto dir = rths_test::TempDir("sweep_chunks");
  const auto spec = SmallSpec(dir, 0.002);
  rths::sweep::SweepOptions whole;
  whole.out = dir / "whole";
  whole.jobs = 2;
  const std::string table = Read(rths::sweep::RunSweep(spec, whole).table);
  rths::sweep::SweepOptions part;
  part.out = dir / "chunked";
  part.chunks = 3;
  std::int64_t ran = 0;
  std::string last;
  for (part.chunk = 0; part.chunk < 3; ++part.chunk) {
    const auto r = rths::sweep::RunSweep(spec, part);
    ran += r.ran;
    last = Read(r.table);
  }
  CHECK(ran == 4);
  // Every recorded number bit for bit (steps/s, a rate, is not recorded here).
  CHECK(last == table);
  part.chunk = 3;
  CHECK_THROWS_AS(rths::sweep::RunSweep(spec, part), rths::Error);
}

TEST_CASE("a drawn value out of its key's range is a row with its status, not a crash of the sweep") {
  const auto dir = rths_test::TempDir("sweep_invalid");
  const auto spec = SmallSpec(dir, 1.0);  // damping ratios far outside their range for some draws
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  o.jobs = 2;
  const auto r = rths::sweep::RunSweep(spec, o);
  CHECK(r.ran == 4);
  CHECK(r.failed > 0);
  int invalid = 0;
  for (int i = 0; i < 4; ++i) {
    const auto row = nlohmann::json::parse(Read(o.out / "rows" / (std::to_string(i) + ".json")));
    const std::string status = row["status"];
    if (status.rfind("invalid: ", 0) == 0) {
      ++invalid;
      CHECK(status.find("structure.damping_ratio") != std::string::npos);
    }
  }
  CHECK(invalid == r.failed);
}

TEST_CASE("the results: table.h5 holds table.csv's columns (read by Python's h5py), summary.csv per group, plots") {
  rths_test::RequireFile("/usr/bin/python3", "python3");
  const auto dir = rths_test::TempDir("sweep_results");
  const auto spec = SmallSpec(dir, 1.0);  // some rows invalid: null cells and failures in the summary
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  o.jobs = 2;
  const auto r = rths::sweep::RunSweep(spec, o);
  REQUIRE(r.failed > 0);
  REQUIRE(r.failed < 4);
  // Python writes table.h5 back out as CSV, each float as its shortest round-trip text (repr),
  // strings decoded, NaN as an empty cell: it must be table.csv byte for byte.
  const fs::path py = dir / "h5_to_csv.py";
  std::ofstream(py) << "import sys, math, h5py\n"
                       "g = h5py.File(sys.argv[1], 'r')['runs']\n"
                       "cols = list(g.attrs['columns'])\n"
                       "def cell(d, i):\n"
                       "    if d.dtype.kind == 'O':\n"
                       "        s = d.asstr()[i]\n"
                       "        return '\"' + s.replace('\"', '\"\"') + '\"' if any(c in s for c in ',\"\\n') else s\n"
                       "    v = d[i]\n"
                       "    if d.dtype.kind == 'f':\n"
                       "        return '' if math.isnan(v) else (repr(float(v)) if v != int(v) or abs(v) >= 1e16 else str(int(v)))\n"
                       "    return str(int(v))\n"
                       "n = len(g[cols[0]])\n"
                       "print(','.join(cols))\n"
                       "for i in range(n): print(','.join(cell(g[c], i) for c in cols))\n";
  const auto got = rths::io::RunCommand({"/usr/bin/python3", py.string(), (o.out / "table.h5").string(), "-"});
  INFO(got.output);
  REQUIRE_MESSAGE(got.output.find("No module named 'h5py'") == std::string::npos,
                  "h5py is not installed: apt-get install python3-h5py (scripts/bootstrap.sh --tests installs it)");
  REQUIRE(got.status == 0);
  CHECK(got.output == Read(r.table));
  // summary.csv: a line per group (controller) and numeric field; the failures counted.
  const std::string summary = Read(o.out / "summary.csv");
  CHECK(summary.rfind("case,controller.kind,field,runs,failures,n,mean,std,min,max\n", 0) == 0);
  int lines = 0, failures = 0;
  std::istringstream in(summary);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    ++lines;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    REQUIRE(cells.size() >= 7);
    CHECK(cells[3] == "2");  // two draws per controller
    if (cells[2] == "steps") failures += std::stoi(cells[4]);
  }
  CHECK(lines == 6);  // 2 groups x 3 fields
  CHECK(failures == r.failed);
  CHECK(fs::file_size(o.out / "plots" / "tracking_nrmse_pct.png") > 1000);
}

TEST_CASE("cases: a case column, by file name, or by path where two cases share a name") {
  const auto dir = rths_test::TempDir("sweep_cases");
  for (const char* sub : {"a", "b"}) {
    fs::create_directories(dir / sub);
    std::ofstream(dir / sub / "base.toml") << "[run]\nname = \"case_" << sub << "\"\nduration_s = 0.05\n";
  }
  std::ofstream(dir / "spec.toml") << "[sweep]\nrecord = [\"steps\"]\n[cases]\nfiles = [\"a/base.toml\", \"b/base.toml\"]\n"
                                   << "[grid]\n\"controller.kind\" = [\"none\", \"ff\"]\n";
  const auto spec = rths::sweep::LoadSpec((dir / "spec.toml").string());
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  o.jobs = 2;
  const auto r = rths::sweep::RunSweep(spec, o);
  REQUIRE(r.not_completed == 0);
  const std::string table = Read(r.table);
  CHECK(table.rfind("index,status,scenario_sha256,case,controller.kind,steps\n", 0) == 0);
  CHECK(table.find(",a/base.toml,none,100\n") != std::string::npos);
  CHECK(table.find(",b/base.toml,ff,100\n") != std::string::npos);
  const std::string summary = Read(o.out / "summary.csv");
  // One run per group: its sample standard deviation (n - 1) is undefined, an empty cell.
  CHECK(summary.find("b/base.toml,ff,steps,1,0,1,100,,100,100\n") != std::string::npos);
  CHECK(fs::exists(o.out / "plots" / "steps.png"));
}

TEST_CASE("a PI's gains swept: array levels of a grid and a drawn element, in the rows, the table and each run") {
  const auto dir = rths_test::TempDir("sweep_pi");
  const fs::path base = rths_test::WriteScenario(
      dir, "[run]\nname = \"sweep_pi\"\nduration_s = 0.05\n[controller]\nkind = \"lti\"\n"
           "[controller.lti]\nfeedback = { num = [0.5, 2.0], den = [1.0, 0.0] }\n");
  std::ofstream(dir / "spec.toml") << "[sweep]\nname = \"pi\"\nbase = \"" << base.string() << "\"\nseed = 9\ndraws = 2\n"
                                   << "record = [\"steps\"]\n"
                                   << "[grid]\n\"controller.lti.feedback.den\" = [[1, 0], [1.0, 10.0]]\n"
                                   << "[draw]\n\"controller.lti.feedback.num[0]\" = { dist = \"uniform\", lo = 0.4, hi = 0.6 }\n";
  const auto spec = rths::sweep::LoadSpec((dir / "spec.toml").string());
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  o.jobs = 2;
  const auto r = rths::sweep::RunSweep(spec, o);
  REQUIRE(r.not_completed == 0);
  REQUIRE(r.rows == 4);
  const std::string table = Read(r.table);
  CHECK(table.rfind("index,status,scenario_sha256,controller.lti.feedback.den,controller.lti.feedback.num[0],steps\n", 0) == 0);
  const auto row3 = nlohmann::json::parse(Read(o.out / "rows" / "3.json"));
  CHECK(row3["set"]["controller.lti.feedback.den"] == "[1.0, 10.0]");  // the level's text
  const double k_p = row3["set"]["controller.lti.feedback.num[0]"].get<double>();
  CHECK(table.find(",\"[1.0, 10.0]\"," + fmt::format("{}", k_p) + ",100\n") != std::string::npos);
  CHECK(table.find(",\"[1, 0]\",") != std::string::npos);
  // The run's scenario: the drawn gain, the file's integral gain, the grid's denominator.
  const auto s = rths::scenario::LoadScenario((o.out / "runs" / "3" / "scenario.toml").string());
  CHECK(s.controller.lti.feedback.num == std::vector<double>{k_p, 2.0});
  CHECK(s.controller.lti.feedback.den == std::vector<double>{1.0, 10.0});
  // summary.csv groups by the level's text.
  CHECK(Read(o.out / "summary.csv").find("\"[1.0, 10.0]\",steps,2,0,2,100,0,100,100\n") != std::string::npos);
}

TEST_CASE("a sweep's model-based controller designs on the plant it drives, as rths run does") {
  // Issue 43: ff_lqg on a benchmark scenario was designed on the damper rig's "avg" servo model.
  const auto dir = rths_test::TempDir("sweep_design_model");
  std::ofstream(dir / "spec.toml") << "[sweep]\nname = \"design\"\nbase = \"" << RTHS_SOURCE_DIR
                                   << "/scenarios/benchmark/case2_example.toml\"\nrecord = [\"steps\"]\n"
                                   << "[set]\n\"run.duration_s\" = 0.05\n"
                                   << "[grid]\n\"controller.kind\" = [\"ff_lqg\", \"lti\"]\n";
  const auto spec = rths::sweep::LoadSpec((dir / "spec.toml").string());
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  const auto r = rths::sweep::RunSweep(spec, o);
  REQUIRE(r.not_completed == 0);
  REQUIRE(r.design_notes.size() == 1);  // ff_lqg's; lti uses no model
  CHECK(r.design_notes[0].find("designed on the benchmark plant's Gp") != std::string::npos);
  const auto s = rths::scenario::LoadScenario((o.out / "runs" / "0" / "scenario.toml").string());
  CHECK(s.controller.kind == rths::control::ControllerKind::kFfLqg);
  CHECK(s.controller.model.name == "custom");  // the fit, written into the run's scenario
}

// --- plots (issue 43 item 7): a line per level of the other factor, points off the frame --------

namespace sweep_plots {

/// A table of `field` over the grid controller.kind x structure.damping_ratio (and `draws` runs
/// per point), row i's value `value(kind, zeta, draw)`; one row not completed.
rths::sweep::Table GridTable(const rths::sweep::Spec& spec, double (*value)(int, double, int)) {
  rths::sweep::Table t;
  t.columns = rths::sweep::TableColumns(spec);
  const std::int64_t per = std::max<std::int64_t>(spec.draws, 1);
  std::int64_t i = 0;
  for (int k = 0; k < 2; ++k) {
    for (const double zeta : {0.01, 0.02, 0.05}) {
      for (int d = 0; d < per; ++d, ++i) {
        std::vector<nlohmann::json> row = {i, i == 3 ? "failed: x" : "completed", "sha"};
        if (spec.grid.size() == 2) row.push_back(k == 0 ? "none" : "ff");
        row.push_back(zeta);
        row.push_back(value(k, zeta, d));
        t.rows.push_back(row);
        t.group.push_back(i / per);
      }
    }
  }
  return t;
}

}  // namespace sweep_plots

TEST_CASE("sweep plots: two factors, each field against one with a line per level of the other, off the frame") {
  const auto dir = rths_test::TempDir("sweep_plots_two");
  rths::sweep::Spec spec;
  spec.name = "two";
  spec.cases = {"base.toml"};
  spec.record = {"tracking_nrmse_pct"};
  spec.grid = {{"controller.kind", {"none", "ff"}}, {"structure.damping_ratio", {"0.01", "0.02", "0.05"}}};
  const auto t = sweep_plots::GridTable(spec, [](int k, double zeta, int) { return (k + 1) * 100.0 * zeta; });
  const auto pngs = rths::sweep::WritePlots(spec, t, dir);
  REQUIRE(pngs.size() == 1);
  const auto curves = rths_test::ReadPlotData(dir / "tracking_nrmse_pct.dat");
  // Against the controller: a line per damping ratio (row 3, zeta 0.01 of ff, failed, is left out).
  const auto by_kind = rths_test::PanelCurves(curves, 1);
  REQUIRE(by_kind.size() == 3);
  CHECK(by_kind[0].title == "0.01");
  CHECK(by_kind[0].x == std::vector<double>{0.0});  // none only: ff's run failed
  CHECK(by_kind[2].title == "0.05");
  CHECK(by_kind[2].x == std::vector<double>{0.0, 1.0});
  CHECK(by_kind[2].y == std::vector<double>{5.0, 10.0});
  // Against the damping ratio: a line per controller, through its points in x order.
  const auto by_zeta = rths_test::PanelCurves(curves, 2);
  REQUIRE(by_zeta.size() == 2);
  CHECK(by_zeta[0].title == "none");
  CHECK(by_zeta[0].x == std::vector<double>{0.01, 0.02, 0.05});
  CHECK(by_zeta[1].title == "ff");
  CHECK(by_zeta[1].x == std::vector<double>{0.02, 0.05});
  CHECK(by_zeta[1].y == std::vector<double>{4.0, 10.0});
  const std::string gp = rths_test::Slurp(dir / "tracking_nrmse_pct.gp");
  for (int p = 1; p <= 2; ++p) {
    CAPTURE(p);
    const std::string panel = rths_test::PanelScript(gp, p);
    CHECK(panel.find("set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05") != std::string::npos);
    CHECK(panel.find("with linespoints") != std::string::npos);
    CHECK(panel.find("set key on outside right top") != std::string::npos);
    CHECK(panel.find("set rmargin 14") != std::string::npos);  // the key's column: "0.01" + 10, not 40 % of the width
    CHECK(panel.find("lc rgb '#D55E00'") != std::string::npos);  // the second level's colour
  }
  CHECK(rths_test::PanelScript(gp, 1).find("set title 'a curve per structure.damping_ratio'") != std::string::npos);
}

TEST_CASE("sweep plots: one factor with draws, a line through the means, the runs as points, off the frame") {
  const auto dir = rths_test::TempDir("sweep_plots_one");
  rths::sweep::Spec spec;
  spec.name = "one";
  spec.cases = {"base.toml"};
  spec.record = {"peak_force_kN"};
  spec.draws = 2;
  spec.grid = {{"structure.damping_ratio", {"0.01", "0.02", "0.05"}}};
  spec.draw = {rths::sweep::Draw{}};
  spec.draw[0].key = "plant.noise_seed";
  spec.draw[0].dist = "seed";
  auto t = sweep_plots::GridTable(spec, [](int k, double zeta, int d) { return 100.0 * zeta + k + d; });
  for (auto& row : t.rows) row.insert(row.end() - 1, nlohmann::json(7));  // the seed column
  REQUIRE(t.columns.size() == t.rows[0].size());
  REQUIRE(rths::sweep::WritePlots(spec, t, dir).size() == 1);
  const auto curves = rths_test::PanelCurves(rths_test::ReadPlotData(dir / "peak_force_kN.dat"), 1);
  REQUIRE(curves.size() == 2);  // the runs, then the line through their means
  CHECK(curves[0].title.empty());
  CHECK(curves[1].x == std::vector<double>{0.01, 0.02, 0.05});
  // The mean of a point's completed runs: zeta 0.01 holds 1, 2, 2, 3; at 0.02 row 3 (3) failed: 2, 3, 4.
  CHECK(curves[1].y[0] == doctest::Approx(2.0));
  CHECK(curves[1].y[1] == doctest::Approx(3.0));
  CHECK(curves[0].x.size() == 11);
  const std::string gp = rths_test::Slurp(dir / "peak_force_kN.gp");
  CHECK(gp.find("set offsets graph 0.05") != std::string::npos);
  CHECK(gp.find("with linespoints") != std::string::npos);
  CHECK(gp.find("set key off") != std::string::npos);
}

TEST_CASE("sweep plots: a Monte Carlo alone (no case or grid axis) is drawn as points, and its title says no lines") {
  const auto dir = rths_test::TempDir("sweep_plots_draws_only");
  const fs::path base = rths_test::WriteScenario(dir, "[run]\nname = \"mc\"\nduration_s = 0.05\n");
  std::ofstream(dir / "spec.toml") << "[sweep]\nname = \"mc\"\nbase = \"" << base.string() << "\"\nseed = 5\ndraws = 3\n"
                                   << "record = [\"peak_force_kN\"]\n"
                                   << "[draw]\n\"structure.damping_ratio\" = { dist = \"uniform\", lo = 0.01, hi = 0.05 }\n";
  const auto spec = rths::sweep::LoadSpec((dir / "spec.toml").string());
  rths::sweep::SweepOptions o;
  o.out = dir / "out";
  const auto r = rths::sweep::RunSweep(spec, o);
  REQUIRE(r.not_completed == 0);
  const std::string gp = rths_test::Slurp(o.out / "plots" / "peak_force_kN.gp");
  CHECK(gp.find("against each axis (completed runs)") != std::string::npos);
  CHECK(gp.find("lines through the mean") == std::string::npos);
}

TEST_CASE("sweep plots: array levels labelled as written, a level that failed everywhere named, ticks that fit") {
  const auto dir = rths_test::TempDir("sweep_plots_labels");
  rths::sweep::Spec spec;
  spec.name = "labels";
  spec.cases = {"base.toml"};
  spec.record = {"peak_force_kN"};
  spec.draws = 4;
  spec.grid = {{"controller.lti.feedback.den", {"[1, 0]", "[1.0, 10.0]", "[1, 100]"}}};
  spec.draw = {rths::sweep::Draw{}};
  spec.draw[0].key = "controller.lti.feedback.num[0]";
  spec.draw[0].dist = "uniform";
  rths::sweep::Table t;
  t.columns = rths::sweep::TableColumns(spec);
  std::int64_t i = 0;
  for (const std::string level : {"[1, 0]", "[1.0, 10.0]", "[1, 100]"}) {
    for (int d = 0; d < 4; ++d, ++i) {
      const double gain = 0.000123456 + 0.0001234567 * static_cast<double>(i);  // long tick labels
      const bool failed = level == "[1, 100]";
      t.rows.push_back({i, failed ? "failed: unstable" : "completed", "sha", level, gain,
                        failed ? nlohmann::json() : nlohmann::json(1.0 + gain)});
      t.group.push_back(i / 4);
    }
  }
  REQUIRE(t.columns.size() == t.rows[0].size());
  REQUIRE(rths::sweep::WritePlots(spec, t, dir).size() == 1);
  const std::string gp = rths_test::Slurp(dir / "peak_force_kN.gp");
  INFO(gp);
  // Against the denominator: its levels as the SPEC writes them, without the CSV's quotes.
  const std::string by_den = rths_test::PanelScript(gp, 1);
  CHECK(by_den.find("'[1.0, 10.0]' 1") != std::string::npos);
  CHECK(by_den.find("\"[1.0, 10.0]\"") == std::string::npos);
  CHECK(by_den.find("set title 'no completed run: [1, 100]'") != std::string::npos);  // its empty tick named
  // Against the drawn gain, a curve per denominator: the one with no completed run is named.
  const std::string by_gain = rths_test::PanelScript(gp, 2);
  CHECK(by_gain.find("coloured by controller.lti.feedback.den; no completed run: [1, 100]") != std::string::npos);
  const auto curves = rths_test::PanelCurves(rths_test::ReadPlotData(dir / "peak_force_kN.dat"), 2);
  REQUIRE(curves.size() == 2);
  CHECK(curves[1].title == "[1.0, 10.0]");
  // Its ticks: a fixed step with few enough labels ("0.0012" is 6 characters) for a narrow panel.
  const std::size_t at = by_gain.find("set xtics ");
  REQUIRE(at != std::string::npos);
  const double step = std::strtod(by_gain.c_str() + at + 10, nullptr);
  REQUIRE(step > 0);
  const double span = 0.0001234567 * 7;  // the completed runs' gains and the failed ones' too
  CHECK(span / step + 1 <= 5.0);
  CHECK(rths::io::NiceTicStep(0.0, 0.00095, 5) == doctest::Approx(0.0005));
  CHECK(rths::io::NiceTicStep(0.0, 1.0, 11) == doctest::Approx(0.1));
  CHECK(rths::io::NiceTicStep(3.0, 3.0, 5) == 0.0);
}
