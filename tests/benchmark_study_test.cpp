// `rths reproduce benchmark --quick` (report/benchmark_study.h, docs/benchmark.md): the
// identification finds the plant's gain and lag, the CSV has the columns and rows, the
// model-based controllers beat `none` on the criteria they target, the perturbed plants are the
// seeded draws, and a perturbed run whose log was removed comes back bit for bit from its
// scenario.toml.
#include <cmath>
#include <map>
#include <set>
#include <string>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "io/benchmark_run.h"
#include "io/csv.h"
#include "io/run_log.h"
#include "report/benchmark_study.h"
#include "test_support.h"

using namespace rths;
using rths_test::TempDir;

namespace {

double Num(const std::string& s) {
  std::size_t used = 0;
  const double v = std::stod(s, &used);
  CHECK(used == s.size());
  return v;
}

}  // namespace

TEST_CASE("reproduce benchmark --quick: identification, benchmark.csv, controllers, perturbed plants, reruns") {
  const auto dir = TempDir("benchmark_quick");
  report::ReproduceOptions o;
  o.out_dir = dir / "out";
  o.quick = true;
  o.jobs = 2;
  o.log = [](std::string_view line) { MESSAGE(std::string(line)); };
  const report::BenchmarkResult res = report::ReproduceBenchmark(o);

  // Identification: the 3-pole model has the plant's DC gain and low-frequency lag.
  const auto& id = res.id;
  CHECK(id.plant_dc_gain == doctest::Approx(1.0075).epsilon(1e-3));
  // A 3-pole fit of a 5th-order plant: its DC gain within 3 % (measured: 1.5 % high).
  CHECK(std::abs(id.fit.fit.model.DcGain() / id.plant_dc_gain - 1.0) < 0.03);
  CHECK(id.plant_lag_ms > 23.0);
  CHECK(id.plant_lag_ms < 27.0);
  CHECK(std::abs(id.model_lag_ms - id.plant_lag_ms) < 1.5);

  // benchmark.csv: the header, 5 controllers x (nominal + 2 perturbed).
  const auto csv = io::ReadCsvFile(o.out_dir / "benchmark.csv");
  REQUIRE(csv.size() == 1 + 5 * (1 + report::kBenchmarkQuickPerturbed));
  CHECK(csv[0] == std::vector<std::string>{"controller", "run", "J1_ms", "J2_pct", "J3_pct", "J4_pct", "J5_pct",
                                           "J6_pct", "J7_pct", "J8_pct", "J9_pct"});
  std::map<std::string, std::map<std::string, std::vector<double>>> j;  // controller -> run -> J1..J9
  const std::set<std::string> controllers{"none", "poly3", "lead", "ff", "ff_lqg"};
  for (std::size_t i = 1; i < csv.size(); ++i) {
    REQUIRE(csv[i].size() == 11);
    CHECK(controllers.count(csv[i][0]) == 1);
    CHECK((csv[i][1] == "nominal" || csv[i][1] == "1" || csv[i][1] == "2"));
    std::vector<double> v;
    for (int c = 2; c < 11; ++c) v.push_back(csv[i][c] == "nan" ? NAN : Num(csv[i][c]));
    // J1 to 0.1 ms, the others to 0.01 %.
    if (std::isfinite(v[0])) CHECK(std::abs(10 * v[0] - std::round(10 * v[0])) < 1e-9);
    j[csv[i][0]][csv[i][1]] = v;
  }
  CHECK(j.size() == 5);

  // No controller: the plant lags about 25 ms, beyond J1's search (50 samples: at most 49 dt =
  // 11.96 ms at 4096 Hz), so J1 sits at its cap.
  const auto& none = j["none"]["nominal"];
  CHECK(none[0] == doctest::Approx(12.0));
  // The model-based controllers remove most of it and of the tracking error, on every plant.
  for (const char* c : {"ff", "ff_lqg"}) {
    for (const char* run : {"nominal", "1", "2"}) {
      INFO(c, " ", run);
      const auto& v = j[c][run];
      CHECK(v[0] <= 2.0);                // J1 [ms]
      CHECK(v[1] < 0.25 * j["none"][run][1]);  // J2: RMS tracking error
      CHECK(v[3] < j["none"][run][3]);   // J4: vs the reference structure
    }
  }
  // The numerical floors follow the reference more closely with ff than without a controller.
  CHECK(j["ff"]["nominal"][5] < none[5]);  // J6

  // The perturbed plants are the seeded draws, written into their scenarios.
  for (int i = 1; i <= report::kBenchmarkQuickPerturbed; ++i) {
    const auto run_dir = o.out_dir / "runs" / fmt::format("ff-{}", i);
    const auto s = scenario::LoadScenario((run_dir / "scenario.toml").string());
    CHECK(s.plant.benchmark.params == models::PerturbedBenchmarkParams(models::BenchmarkPlantParams{}, i));
    CHECK(!std::filesystem::exists(run_dir / "log.lcm"));  // removed once scored
  }
  CHECK(std::filesystem::exists(o.out_dir / "runs" / "ff-nominal" / "log.lcm"));
  CHECK(std::filesystem::exists(o.out_dir / "benchmark.md"));

  // A removed log comes back bit for bit: rerun ff-1's scenario and score it again.
  const auto rerun = dir / "rerun";
  const auto s = scenario::LoadScenario((o.out_dir / "runs" / "ff-1" / "scenario.toml").string());
  const auto r = report::RunBatch({{"rerun ff 1", s, rerun}}, 1);
  REQUIRE(r[0].ok);
  const auto again = io::BenchmarkCriteriaOfRun((rerun / "log.lcm").string(), scenario::LoadScenario((rerun / "scenario.toml").string()));
  const report::BenchmarkRow* row = nullptr;
  for (const auto& x : res.rows) {
    if (x.controller == "ff" && x.run == "1") row = &x;
  }
  REQUIRE(row != nullptr);
  CHECK(again.J1_ms == row->j.J1_ms);
  CHECK(again.J2_pct == row->j.J2_pct);
  CHECK(again.J4_pct == row->j.J4_pct);
  CHECK(again.J9_pct == row->j.J9_pct);
}
