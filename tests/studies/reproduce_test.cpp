// `rths reproduce`: the library functions tools/reproduce.cpp calls (lib/studies/),
// run here directly. fig5 against the E6 reference peaks; table2 --quick on the linear plant:
// the file's shape (RFC 4180, exact header and names), its numbers against the paper's Table 2
// and the independent computations of docs/experiments.md E3 / docs/models.md section 10, and the claims
// written into table2.md against the numbers in table2.csv.
#include <doctest/doctest.h>

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/csv.h"
#include "studies/fig5.h"
#include "studies/fig6.h"
#include "studies/fig78.h"
#include "studies/table2.h"
#include "scenario/scenario.h"
#include "test_support.h"

using namespace rths::studies;
using rths_test::TempDir;
using rths_test::Slurp;
using rths_test::Number;
namespace fs = std::filesystem;

namespace {

bool IsPng(const fs::path& p) {
  const std::string s = Slurp(p);
  return s.size() > 1000 && s.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8);
}

// Table 2 of the paper, typed in here again (not taken from the library) so that a typo in
// either shows up.
struct PaperRow {
  const char* condition;
  const char* controller;
  const char* pct_5;
  const char* pct_15;
};
const PaperRow kPaper[] = {
    {"0.0A", "None", "16.0", "42.9"},           {"0.0A", "3rd Poly 8ms", "1.22", "12.8"},
    {"0.0A", "Lead Comp 8ms", "1.95", "13.3"},  {"0.0A", "G_FF,0.0A + LP", "1.01", "4.27"},
    {"0.0A", "G_FF,0.0A", "0.942", "3.45"},     {"0.0A", "G_FF,avgA + LQG", "1.16", "3.89"},
    {"2.5A", "None", "20.1", "51.7"},           {"2.5A", "3rd Poly 10ms", "2.04", "25.9"},
    {"2.5A", "Lead Comp 10ms", "3.34", "15.1"}, {"2.5A", "G_FF,2.5A + LP", "2.55", "9.40"},
    {"2.5A", "G_FF,2.5A", "2.27", "4.68"},      {"2.5A", "G_FF,avgA + LQG", "1.41", "5.57"},
    {"pulse", "None", "18.1", "49.2"},          {"pulse", "3rd Poly 9ms", "1.80", "18.3"},
    {"pulse", "Lead Comp 9ms", "2.97", "16.0"}, {"pulse", "Bumpless + LP", "2.04", "8.45"},
    {"pulse", "G_FF,avgA", "1.93", "6.35"},     {"pulse", "G_FF,avgA + LQG", "1.09", "4.72"},
};

}  // namespace

TEST_CASE("fig5 (E6): the six peaks within 2 % of the reference, the CSV and the PNG") {
  const auto dir = TempDir("fig5");
  ReproduceOptions opts;
  opts.out_dir = dir / "out";
  opts.quick = true;
  const Fig5Result r = ReproduceFig5(opts);
  const double reference[] = {18.3, 77.9, 139.6, 166.8, 179.7, 187.0};  // docs/experiments.md E6
  REQUIRE(r.ours_peak_kN.size() == 6);
  for (int i = 0; i < 6; ++i) CHECK(r.ours_peak_kN[i] == doctest::Approx(reference[i]).epsilon(0.02));

  const auto csv = rths::io::ReadCsvFile(opts.out_dir / "fig5_peaks.csv");
  REQUIRE(csv.size() == 7);
  CHECK(csv[0] == std::vector<std::string>{"current_A", "paper_peak_kN", "ours_peak_kN"});
  for (int i = 0; i < 6; ++i) {
    CHECK(Number(csv[i + 1][0]) == doctest::Approx(0.5 * i));
    CHECK(Number(csv[i + 1][1]) == doctest::Approx(reference[i]));
    CHECK(Number(csv[i + 1][2]) == doctest::Approx(reference[i]).epsilon(0.02));
  }
  CHECK(IsPng(opts.out_dir / "fig5.png"));
  const std::string gp = Slurp(opts.out_dir / "fig5.gp");
  for (const char* label : {"Force [kN]", "Displacement [mm]", "Velocity [mm/s]", "Time [s]", "2.5 A"}) {
    CHECK(gp.find(label) != std::string::npos);
  }
  // Never overwrite a folder that holds something.
  CHECK_THROWS_WITH_AS(ReproduceFig5(opts), doctest::Contains("not empty"), rths::Error);
}

TEST_CASE("plant choice: linear always, physical only if it really runs, anything else refused") {
  const auto dir = TempDir("plant_probe");
  CHECK_NOTHROW(RequirePlant("linear", dir));
  CHECK_THROWS_WITH_AS(RequirePlant("hydraulic", dir), doctest::Contains("physical, linear"), rths::Error);
  try {
    RequirePlant("physical", dir);
    MESSAGE("the physics-based plant is available");
  } catch (const rths::Error& e) {
    MESSAGE(e.what());
    CHECK(std::string(e.what()).find("--plant linear") != std::string::npos);
  }
  CHECK(fs::is_empty(dir));  // the probe cleans up after itself
}

TEST_CASE("table2 --quick on the linear plant") {
  const auto dir = TempDir("table2");
  ReproduceOptions opts;
  opts.out_dir = dir / "out";
  opts.quick = true;
  opts.plant = "linear";
  opts.jobs = 2;
  const Table2Result result = ReproduceTable2(opts);
  MESSAGE("table2 --quick --plant linear: " << result.wall_s << " s");

  // --- table2.csv: RFC 4180, exact header, 36 rows, exact names in the paper's order ---
  const std::string raw = Slurp(opts.out_dir / "table2.csv");
  CHECK(raw.rfind("condition,controller,band_hz,paper_pct,ours_pct\r\n", 0) == 0);
  CHECK(raw.find("\"G_FF,0.0A + LP\"") != std::string::npos);   // names with commas are quoted
  CHECK(raw.find("\"G_FF,avgA + LQG\"") != std::string::npos);
  CHECK(raw.find(",Bumpless + LP,") != std::string::npos);      // and names without are not
  const auto csv = rths::io::ReadCsvFile(opts.out_dir / "table2.csv");
  REQUIRE(csv.size() == 37);
  CHECK(csv[0] == std::vector<std::string>{"condition", "controller", "band_hz", "paper_pct", "ours_pct"});
  std::map<std::string, double> ours;  // "cond|controller|band" -> ours_pct
  std::size_t i = 1;
  for (const auto& p : kPaper) {
    for (const char* band : {"0-5", "0-15"}) {
      REQUIRE(i < csv.size());
      const auto& row = csv[i++];
      REQUIRE(row.size() == 5);
      CHECK(row[0] == p.condition);
      CHECK(row[1] == p.controller);
      CHECK(row[2] == band);
      CHECK(row[3] == (std::string(band) == "0-5" ? p.pct_5 : p.pct_15));
      const double v = Number(row[4]);
      CHECK_MESSAGE(std::isfinite(v), row[4]);
      CHECK(v > 0.0);
      CHECK(v < 100.0);
      ours[std::string(p.condition) + "|" + p.controller + "|" + band] = v;
    }
  }
  auto at = [&](const char* c, const char* n, const char* b) {
    return ours.at(std::string(c) + "|" + n + "|" + b);
  };

  // --- the "None" rows ---
  // 0.0 A and 2.5 A: within 2.5 points of the paper (E3). The quick None rows run 20 s: with
  // seed 1 they are within 0.5 points of the 60 s values (see table2.cpp).
  CHECK(at("0.0A", "None", "0-5") == doctest::Approx(16.0).epsilon(2.5 / 16.0));
  CHECK(at("0.0A", "None", "0-15") == doctest::Approx(42.9).epsilon(2.5 / 42.9));
  CHECK(at("2.5A", "None", "0-5") == doctest::Approx(20.1).epsilon(2.5 / 20.1));
  CHECK(at("2.5A", "None", "0-15") == doctest::Approx(51.7).epsilon(2.5 / 51.7));
  // Under the pulse the linear plant is Eq. 30 (the brief: pulse -> "avg"), which does not feel the
  // current: its None error is Eq. 30's, computed independently as 16.5 / 46.1 % with a ZOH at
  // 2 kHz (docs/experiments.md E3), against the paper's 18.1 / 49.2. Check against that computation
  // (+/- 2 points for a finite record); 49.2 is out of reach of this plant, and table2.md says so.
  CHECK(at("pulse", "None", "0-5") == doctest::Approx(16.5).epsilon(2.0 / 16.5));
  CHECK(at("pulse", "None", "0-15") == doctest::Approx(46.1).epsilon(2.0 / 46.1));

  // --- compensated rows against the independent linear computation (docs/models.md section 10):
  // FF matching the plant 0.46 / 1.33 %, FF + LP 2.33 / 6.98 %, 3rd Poly 8 ms 0.63 / 3.42 %.
  // Quick (6 s) records: a wide band, but an off-by-one step (1.4 / 4.0 %) would fail it.
  CHECK(at("0.0A", "G_FF,0.0A", "0-5") == doctest::Approx(0.46).epsilon(0.3));
  CHECK(at("0.0A", "G_FF,0.0A", "0-15") == doctest::Approx(1.33).epsilon(0.3));
  CHECK(at("2.5A", "G_FF,2.5A", "0-15") == doctest::Approx(1.33).epsilon(0.3));
  CHECK(at("0.0A", "G_FF,0.0A + LP", "0-15") == doctest::Approx(6.98).epsilon(0.3));
  CHECK(at("0.0A", "3rd Poly 8ms", "0-15") == doctest::Approx(3.42).epsilon(0.3));

  // --- the claims: the library's verdicts agree with the numbers in the CSV ---
  bool c1 = true;
  const std::map<std::string, std::vector<const char*>> groups{
      {"0.0A", {"G_FF,0.0A", "None", "3rd Poly 8ms", "Lead Comp 8ms"}},
      {"2.5A", {"G_FF,2.5A", "None", "3rd Poly 10ms", "Lead Comp 10ms"}},
      {"pulse", {"G_FF,avgA", "None", "3rd Poly 9ms", "Lead Comp 9ms"}}};
  for (const auto& [cond, names] : groups) {
    for (std::size_t j = 1; j < names.size(); ++j) {
      c1 = c1 && at(cond.c_str(), names[0], "0-15") < at(cond.c_str(), names[j], "0-15");
    }
  }
  const bool c2 = at("pulse", "G_FF,avgA + LQG", "0-5") < at("pulse", "G_FF,avgA", "0-5") &&
                  at("pulse", "G_FF,avgA + LQG", "0-15") < at("pulse", "G_FF,avgA", "0-15");
  bool c3 = true, c4 = true;
  for (const auto& p : kPaper) {
    for (const char* band : {"0-5", "0-15"}) {
      const double v = at(p.condition, p.controller, band);
      if (std::string(p.controller) == "None") {
        c4 = c4 && std::abs(v - Number(std::string(band) == "0-5" ? p.pct_5 : p.pct_15)) <= 2.5;
      } else {
        c3 = c3 && v < at(p.condition, "None", band);
      }
    }
  }
  REQUIRE(result.claims.size() == 4);
  CHECK(result.claims[0].holds == c1);
  CHECK(result.claims[1].holds == c2);
  CHECK(result.claims[2].holds == c3);
  CHECK(result.claims[3].holds == c4);
  // On a linear plant (1)-(3) hold (docs/models.md section 10, computed independently).
  CHECK(c1);
  CHECK(c2);
  CHECK(c3);

  const std::string md = Slurp(opts.out_dir / "table2.md");
  CHECK(md.find("**Plant: linear**") != std::string::npos);
  CHECK(md.find("| 0.0A | G_FF,0.0A + LP | 1.01 |") != std::string::npos);
  for (std::size_t k = 0; k < 4; ++k) {
    const std::string verdict = (result.claims[k].holds ? "**Holds:** " : "**Does not hold:** ") + result.claims[k].text;
    CHECK_MESSAGE(md.find(verdict) != std::string::npos, verdict);
  }

  // --- every run kept, with its own scenario file and the hash of that file ---
  std::size_t runs = 0;
  for (const auto& e : fs::directory_iterator(opts.out_dir / "runs")) {
    ++runs;
    const fs::path d = e.path();
    CHECK(fs::exists(d / "log.lcm"));
    const auto s = rths::scenario::LoadScenario((d / "scenario.toml").string());
    const auto j = nlohmann::json::parse(Slurp(d / "summary.json"));
    CHECK(j["scenario_sha256"].get<std::string>() == s.sha256);
    CHECK(j["steps"].get<std::int64_t>() == s.steps());
    CHECK(s.structure.mode == rths::models::StructureMode::kPredefined);
    CHECK(s.plant.specimen == rths::models::Specimen::kMrDamper);
    CHECK(s.plant.kind == rths::models::PlantKind::kLinear);
  }
  CHECK(runs == 36);
}

TEST_CASE("fig6 --quick on the linear plant (E1): the fits recover Eqs. 28 and 29 within 3 %") {
  const auto dir = TempDir("fig6");
  ReproduceOptions opts;
  opts.out_dir = dir / "out";
  opts.quick = true;
  opts.plant = "linear";
  const Fig6Result r = ReproduceFig6(opts);
  REQUIRE(r.claims.size() == 1);
  CHECK(r.claims[0].holds);

  // From the file, against the paper's numbers typed in here (Eqs. 28-30).
  const auto csv = rths::io::ReadCsvFile(opts.out_dir / "fig6_models.csv");
  REQUIRE(csv.size() == 13);
  CHECK(csv[0] == std::vector<std::string>{"condition", "parameter", "paper", "ours", "diff_pct"});
  const std::map<std::string, double> eq{{"0.0A K", 1.730e7}, {"0.0A p", 182.7}, {"0.0A b", 225.3},
                                         {"0.0A c", 9.499e4}, {"2.5A K", 1.613e7}, {"2.5A p", 134.2},
                                         {"2.5A b", 324.6},   {"2.5A c", 1.211e5}, {"avg K", 1.600e7},
                                         {"avg p", 151.7},    {"avg b", 250.4},    {"avg c", 1.061e5}};
  for (std::size_t i = 1; i < csv.size(); ++i) {
    const std::string key = csv[i][0] + " " + csv[i][1];
    REQUIRE(eq.count(key) == 1);
    CHECK(Number(csv[i][2]) == doctest::Approx(eq.at(key)).epsilon(1e-4));
    const double ours = Number(csv[i][3]);
    // E1: 3 % on the linear plants for 0.0 A and 2.5 A; the fit of the averaged response lands
    // near Eq. 30 too (the paper made Eq. 30 that way), within 3 % here.
    CHECK_MESSAGE(ours == doctest::Approx(eq.at(key)).epsilon(0.03), key << ": " << ours);
    CHECK(Number(csv[i][4]) == doctest::Approx(100.0 * (ours / eq.at(key) - 1.0)).epsilon(1e-3).scale(1.0));
  }
  // The measured curves: 0.0 A lags about 7.85 ms and 2.5 A about 10.1 ms at low frequency
  // (docs/models.md section 1, d1/d0, plus half a sample for the hold).
  REQUIRE(r.measured.size() == 2);
  double lag0 = 0, lag25 = 0;
  int n = 0;
  for (std::size_t i = 0; i < r.measured[0].f_hz.size(); ++i) {
    if (r.measured[0].f_hz[i] >= 2.0 && r.measured[0].f_hz[i] <= 4.0) {
      lag0 += r.measured[0].lag_ms[i];
      lag25 += r.measured[1].lag_ms[i];
      ++n;
    }
  }
  REQUIRE(n > 0);
  CHECK(lag0 / n == doctest::Approx(7.85 + 0.25).epsilon(0.05));
  CHECK(lag25 / n == doctest::Approx(10.13 + 0.25).epsilon(0.05));

  CHECK(IsPng(opts.out_dir / "fig6.png"));
  const std::string gp = Slurp(opts.out_dir / "fig6.gp");
  for (const char* label : {"Magnitude [mm/mm]", "Phase [deg]", "Time lag [ms]", "Frequency [Hz]",
                            "title '0.0 A'", "title '2.5 A'", "title 'fitted 3-pole models'"}) {
    CHECK_MESSAGE(gp.find(label) != std::string::npos, label);
  }
  const auto curves = rths::io::ReadCsvFile(opts.out_dir / "fig6.csv");
  CHECK(curves[0] == std::vector<std::string>{"condition", "f_hz", "magnitude", "phase_deg", "time_lag_ms", "coherence"});
}

TEST_CASE("fig7 and fig8 --quick on the linear plant (E2): one curve per controller, E2's shapes") {
  for (const char* figure : {"fig7", "fig8"}) {
    CAPTURE(figure);
    const auto dir = TempDir(figure);
    ReproduceOptions opts;
    opts.out_dir = dir / "out";
    opts.quick = true;
    opts.plant = "linear";
    const Fig78Result r = ReproduceFig78(opts, figure);
    const bool zero = std::string(figure) == "fig7";
    const std::vector<std::string> names =
        zero ? std::vector<std::string>{"None", "3rd Poly 8ms", "Lead Comp 8ms", "G_FF,0.0A + LP", "G_FF,0.0A", "G_FF,avgA + LQG"}
             : std::vector<std::string>{"None", "3rd Poly 10ms", "Lead Comp 10ms", "G_FF,2.5A + LP", "G_FF,2.5A", "G_FF,avgA + LQG"};

    // The CSV: exact header, the six names in order, frequencies over (0, 50] Hz.
    const auto csv = rths::io::ReadCsvFile(opts.out_dir / (std::string(figure) + ".csv"));
    REQUIRE(csv.size() > 6 * 100);
    CHECK(csv[0] == std::vector<std::string>{"controller", "f_hz", "magnitude", "phase_deg", "time_lag_ms", "coherence"});
    std::vector<std::string> seen;
    std::map<std::string, std::vector<std::array<double, 3>>> curve;  // name -> (f, |G|, lag)
    for (std::size_t i = 1; i < csv.size(); ++i) {
      REQUIRE(csv[i].size() == 6);
      if (seen.empty() || seen.back() != csv[i][0]) seen.push_back(csv[i][0]);
      const double f = Number(csv[i][1]);
      CHECK(f > 0.0);
      CHECK(f <= 50.0);
      curve[csv[i][0]].push_back({f, Number(csv[i][2]), Number(csv[i][4])});
    }
    CHECK(seen == names);

    // E2 on a plant equal to the design model, recomputed from the CSV: the proposed FF within
    // 10 % and 1 ms up to 30 Hz; FF + LP a nearly constant lag of about 1.25 ms.
    double ff_mag = 0, ff_lag = 0, lp_sum = 0;
    int lp_n = 0;
    for (const auto& [f, mag, lag] : curve.at(names[4])) {
      if (f >= 0.5 && f <= 30.0) {
        ff_mag = std::max(ff_mag, std::abs(mag - 1.0));
        ff_lag = std::max(ff_lag, std::abs(lag));
      }
    }
    for (const auto& [f, mag, lag] : curve.at(names[3])) {
      if (f >= 2.0 && f <= 30.0) {
        lp_sum += lag;
        ++lp_n;
      }
    }
    CHECK(ff_mag < 0.10);
    CHECK(ff_lag < 1.0);
    REQUIRE(lp_n > 0);
    CHECK(lp_sum / lp_n == doctest::Approx(1.25).epsilon(0.1));
    // None: the plant alone, about 8 / 10 ms of lag at low frequency.
    for (const auto& [f, mag, lag] : curve.at("None")) {
      if (f >= 2.0 && f <= 4.0) CHECK(lag == doctest::Approx(zero ? 8.1 : 10.4).epsilon(0.08));
    }
    // The library's own checks agree, and all hold on the design model.
    REQUIRE(r.claims.size() == 4);
    for (const auto& c : r.claims) CHECK_MESSAGE(c.holds, c.text << ": " << c.detail);

    CHECK(IsPng(opts.out_dir / (std::string(figure) + ".png")));
    const std::string gp = Slurp(opts.out_dir / (std::string(figure) + ".gp"));
    for (const auto& n : names) CHECK_MESSAGE(gp.find("title '" + n + "'") != std::string::npos, n);
    CHECK(gp.find("Time lag [ms]") != std::string::npos);
  }
}
