// The RTHS studies (docs/experiments.md E4, E5): the ideal plant (pure numerical simulation), Fig. 9 and
// Fig. 11 quick reproductions, parallel = serial, and a 9-story lockstep regression.
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "io/csv.h"
#include "studies/batch.h"
#include "studies/fig11.h"
#include "studies/fig9.h"
#include "run_support.h"
#include "test_support.h"

using namespace rths;
using rths_test::TempDir;

namespace {

scenario::Scenario Base(const std::string& name) {
  return scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/" + name);
}

// Writes the scenario into dir/scenario.toml and loads it back (a real file and hash).
scenario::Scenario AsFile(const scenario::Scenario& s, const std::filesystem::path& dir) {
  return studies::WriteScenarioFile({"test", s, dir});
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("ideal plant: y_k == r_k bit for bit, f_k the damper's force, deterministic") {
  auto s = Base("fig9_base.toml");
  s.run.duration_s = 1.0;
  s.structure.frequency_hz = 5.0;
  s.plant.kind = rths::models::PlantKind::kIdeal;
  s.controller.kind = rths::control::ControllerKind::kNone;
  std::string digest[2];
  for (int rep = 0; rep < 2; ++rep) {
    const auto dir = TempDir(fmt::format("ideal_{}", rep));
    const auto sc = AsFile(s, dir);
    const auto r = rths_test::RunMemq({sc}, dir);
    REQUIRE(r.code == 0);
    const auto log = io::ReadRunLog((dir / "log.lcm").string());
    REQUIRE(log.CompleteSteps() == sc.steps());
    double peak_f = 0.0, peak_r = 0.0;
    for (std::int64_t k = 0; k < log.CompleteSteps(); ++k) {
      REQUIRE(SameBits(log.measured[k].y_mm, log.desired[k].r_mm));
      peak_f = std::max(peak_f, std::abs(log.measured[k].f_kN));
      peak_r = std::max(peak_r, std::abs(log.desired[k].r_mm));
    }
    CHECK(peak_r > 0.1);   // the structure moved
    CHECK(peak_f > 0.5);   // and the damper resisted
    CHECK(peak_f < 50.0);
    digest[rep] = io::PayloadDigest(log);
  }
  CHECK(digest[0] == digest[1]);
}

TEST_CASE("fig9 --quick: fig9.csv with the exact header, 36 rows, the Table 2 names; the proposed FF best or "
          "within 10 % of best at f >= 5 Hz") {
  const auto dir = TempDir("fig9_quick");
  studies::ReproduceOptions o;
  o.out_dir = dir / "out";
  o.quick = true;
  o.jobs = 2;
  o.log = [](std::string_view line) { MESSAGE(std::string(line)); };
  const auto res = studies::ReproduceFig9(o);
  const auto csv = io::ReadCsvFile(o.out_dir / "fig9.csv");
  REQUIRE(csv.size() == 37);
  CHECK(csv[0] == std::vector<std::string>{"f_hz", "controller", "rms_pct", "stopped"});
  const std::set<std::string> names{"None", "3rd Poly 8ms", "Lead Comp 8ms", "G_FF,0.0A + LP", "G_FF,0.0A",
                                    "G_FF,avgA + LQG"};
  std::map<double, std::map<std::string, double>> table;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    REQUIRE(csv[i].size() == 4);
    CHECK(names.count(csv[i][1]) == 1);
    std::size_t used = 0;
    const double v = std::stod(csv[i][2], &used);
    CHECK(used == csv[i][2].size());
    CHECK(std::isfinite(v));
    CHECK(!csv[i][3].empty());
    table[std::stod(csv[i][0])][csv[i][1]] = v;
  }
  CHECK(table.size() == 6);
  for (const auto& [f, row] : table) {
    CHECK(row.size() == 6);
    if (f < 5.0) continue;
    double best = 1e300;
    for (const auto& [n, v] : row) best = std::min(best, v);
    INFO(fmt::format("f = {} Hz: G_FF,0.0A {} %, best {} %", f, row.at("G_FF,0.0A"), best));
    CHECK(row.at("G_FF,0.0A") <= 1.10 * best);
  }
  CHECK(std::filesystem::exists(o.out_dir / "fig9.png"));
  CHECK(res.rows.size() == 36);
}

TEST_CASE("fig9: a parallel sweep gives the same numbers as the same runs one at a time") {
  const auto base = Base("fig9_base.toml");
  const auto ctrls = studies::Fig9Controllers();
  std::vector<std::pair<double, std::size_t>> pairs{{5.0, 4}, {20.0, 1}, {1.0, 5}, {30.0, 2}};
  std::vector<studies::RunResult> results[2];
  std::vector<std::string> digests[2];
  for (int mode = 0; mode < 2; ++mode) {
    const auto dir = TempDir(fmt::format("fig9_par_{}", mode));
    std::vector<studies::RunSpec> specs;
    for (const auto& [f, c] : pairs) {
      specs.push_back({fmt::format("{} {}", f, ctrls[c].name),
                       studies::Fig9Scenario(base, f, ctrls[c], "physical", 1.0),
                       dir / studies::Slug(fmt::format("{} {}", f, ctrls[c].name))});
    }
    results[mode] = studies::RunBatch(specs, mode == 0 ? 2 : 1);
    for (const auto& s : specs) digests[mode].push_back(io::PayloadDigest(io::ReadRunLog((s.dir / "log.lcm").string())));
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    CHECK(results[0][i].ok == results[1][i].ok);
    CHECK(SameBits(results[0][i].tracking_pct, results[1][i].tracking_pct));
    CHECK(SameBits(results[0][i].peak_force_kN, results[1][i].peak_force_kN));
    CHECK(digests[0][i] == digests[1][i]);
  }
}

TEST_CASE("9-story lockstep regression: a short run's payload digest is identical across repeats") {
  auto s = Base("fig11_base.toml");
  s.run.duration_s = 0.5;
  s.semiactive.mode = rths::control::SemiactiveMode::kClippedOptimal;
  std::string digest[2];
  for (int rep = 0; rep < 2; ++rep) {
    const auto dir = TempDir(fmt::format("nine_{}", rep));
    const auto sc = AsFile(s, dir);
    REQUIRE(sc.structure.kind == rths::models::StructureKind::kFile);
    const auto r = rths_test::RunMemq({sc}, dir);
    REQUIRE(r.code == 0);
    const auto log = io::ReadRunLog((dir / "log.lcm").string());
    REQUIRE(log.CompleteSteps() == sc.steps());
    CHECK(log.desired.back().n_dof == 9);
    digest[rep] = io::PayloadDigest(log);
  }
  CHECK(digest[0] == digest[1]);
}

TEST_CASE("fig11 --quick: fig11_summary.json with 9 runs, the exact keys and 9-element arrays") {
  const auto dir = TempDir("fig11_quick");
  studies::ReproduceOptions o;
  o.out_dir = dir / "out";
  o.quick = true;
  o.jobs = 2;
  o.log = [](std::string_view line) { MESSAGE(std::string(line)); };
  studies::ReproduceFig11(o);
  std::ifstream in(o.out_dir / "fig11_summary.json");
  REQUIRE(in);
  const auto j = nlohmann::json::parse(in);
  REQUIRE(j.is_object());
  CHECK(j.size() == 1);
  REQUIRE(j["runs"].size() == 9);
  const std::set<std::string> keys{"controller",
                                   "semiactive",
                                   "stopped",
                                   "peak_drift_mm",
                                   "peak_abs_accel_mps2",
                                   "damper_peak_force_kN",
                                   "damper_peak_disp_mm",
                                   "force_rths_vs_numerical_nrmse_pct",
                                   "accel_extrapolation_rms_err_pct",
                                   "velocity_prediction_rms_err_pct"};
  std::set<std::pair<std::string, std::string>> seen;
  for (const auto& r : j["runs"]) {
    std::set<std::string> k;
    for (const auto& [key, v] : r.items()) k.insert(key);
    CHECK(k == keys);
    CHECK(r["peak_drift_mm"].size() == 9);
    CHECK(r["peak_abs_accel_mps2"].size() == 9);
    const std::string mode = r["semiactive"];
    CHECK((mode == "passive_off" || mode == "passive_on" || mode == "clipped_optimal"));
    CHECK(r["stopped"].is_string());
    CHECK(r["damper_peak_force_kN"].get<double>() > 0.0);
    seen.insert({r["controller"], mode});
  }
  CHECK(seen.size() == 9);
  for (const char* png : {"fig11_damper_clipped_optimal.png", "fig11_stories.png"}) {
    CHECK(std::filesystem::exists(o.out_dir / png));
  }
}
