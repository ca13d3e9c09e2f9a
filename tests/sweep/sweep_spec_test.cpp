// A sweep's SPEC (lib/sweep/spec.h): the run count and order, run i's scenario from the SPEC and i
// alone (the same values whatever else the sweep draws), the draws' distributions, and errors
// that name the file, the key and what is allowed.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/error.h"
#include "models/benchmark_plant.h"
#include "scenario/scenario.h"
#include "sweep/element_keys.h"
#include "sweep/spec.h"
#include "scenario_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths::sweep::ParseSpec;
using rths::sweep::PointOf;

namespace {

const char* kSpec = R"(
[sweep]
name = "lqg"
base = "../scenarios/default.toml"
seed = 7
draws = 3
record = ["tracking_nrmse_pct", "status"]
[grid]
"controller.kind" = ["ff", "lti"]
"plant.noise_y_mm_rms" = [0.0, 0.01, 2e-2]
[draw]
"structure.damping_ratio" = { dist = "normal", mean = 0.02, std = 0.002 }
"plant.noise_seed" = { dist = "seed" }
)";

double ValueOf(const std::string& set) { return std::stod(set.substr(set.find('=') + 1)); }

}  // namespace

TEST_CASE("runs and their order: case, grid combination (sorted keys, the last fastest), draw") {
  const auto spec = ParseSpec(kSpec, "/x/sweeps/lqg.toml");
  CHECK(spec.cases == std::vector<std::string>{"/x/scenarios/default.toml"});
  CHECK(spec.combinations() == 6);
  CHECK(spec.runs() == 18);
  CHECK(spec.record == std::vector<std::string>{"tracking_nrmse_pct", "status"});
  const auto p0 = PointOf(spec, 0);
  CHECK(p0.sets[0] == "controller.kind=\"ff\"");
  CHECK(p0.sets[1] == "plant.noise_y_mm_rms=0.0");
  const auto p5 = PointOf(spec, 5);  // combination 1, draw 2
  CHECK(p5.combination == 1);
  CHECK(p5.draw == 2);
  CHECK(p5.sets[1] == "plant.noise_y_mm_rms=0.01");
  const auto p17 = PointOf(spec, 17);
  CHECK(p17.sets[0] == "controller.kind=\"lti\"");
  CHECK(p17.sets[1] == "plant.noise_y_mm_rms=0.02");
  CHECK(p17.sets.size() == 4);  // two grid values, then the two drawn keys in sorted order
  CHECK(p17.sets[2].rfind("plant.noise_seed=", 0) == 0);
  CHECK(p17.sets[3].rfind("structure.damping_ratio=", 0) == 0);
  CHECK_THROWS_AS(PointOf(spec, 18), rths::Error);
  CHECK_THROWS_AS(PointOf(spec, -1), rths::Error);
}

TEST_CASE("run i is made from the SPEC and i alone: another grid or another drawn key leaves its draws alone") {
  const auto spec = ParseSpec(kSpec, "/x/sweeps/lqg.toml");
  // Twice the same: deterministic.
  CHECK(PointOf(spec, 11).sets == PointOf(spec, 11).sets);
  // Different runs draw differently.
  CHECK(PointOf(spec, 11).sets[3] != PointOf(spec, 12).sets[3]);
  // A third drawn key does not change the other keys' values of the same run.
  std::string more = kSpec;
  more += "\"structure.frequency_hz\" = { dist = \"uniform\", lo = 4.0, hi = 6.0 }\n";
  const auto spec2 = ParseSpec(more, "/x/sweeps/lqg.toml");
  const auto a = PointOf(spec, 11), b = PointOf(spec2, 11);
  CHECK(b.sets.size() == 5);
  CHECK(a.sets[2] == b.sets[2]);  // plant.noise_seed
  CHECK(a.sets[3] == b.sets[3]);  // structure.damping_ratio (structure.frequency_hz sorts after it)
  // Another sweep seed: other draws.
  std::string reseeded = kSpec;
  reseeded.replace(reseeded.find("seed = 7"), 8, "seed = 8");
  CHECK(PointOf(ParseSpec(reseeded, "/x/s.toml"), 11).sets[3] != a.sets[3]);
}

TEST_CASE("the draws follow their distributions, and a drawn value reads back as the same double") {
  const auto spec = ParseSpec(R"(
[sweep]
base = "b.toml"
draws = 20000
[draw]
"a" = { dist = "normal", mean = 0.02, std = 0.002 }
"b" = { dist = "uniform", lo = 4.0, hi = 6.0 }
"c" = { dist = "lognormal", mu = 0.0, sigma = 0.1 }
"d" = { dist = "seed" }
)",
                              "/x/s.toml");
  double sum_a = 0, sum2_a = 0, min_b = 1e9, max_b = -1e9, sum_log_c = 0;
  std::set<std::string> seeds;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const auto p = PointOf(spec, i);
    const double a = ValueOf(p.sets[0]), b = ValueOf(p.sets[1]), c = ValueOf(p.sets[2]);
    sum_a += a;
    sum2_a += a * a;
    min_b = std::min(min_b, b);
    max_b = std::max(max_b, b);
    sum_log_c += std::log(c);
    seeds.insert(p.sets[3]);
  }
  const double mean = sum_a / n, sd = std::sqrt(sum2_a / n - mean * mean);
  // Sampling error of the mean: 0.002 / sqrt(20000) = 1.4e-5; allow 5 of them.
  CHECK(std::abs(mean - 0.02) < 7e-5);
  CHECK(std::abs(sd - 0.002) < 1e-4);  // sd of the sd ~ 0.002 / sqrt(40000) = 1e-5
  CHECK(min_b >= 4.0);
  CHECK(max_b < 6.0);
  CHECK(max_b - min_b > 1.99);
  CHECK(std::abs(sum_log_c / n) < 5 * 0.1 / std::sqrt(n));
  CHECK(seeds.size() > n - 5);  // distinct seeds (a few collisions in 2^31 are allowed)
  // The literal of a drawn double is the double.
  const auto p = PointOf(spec, 3);
  CHECK(ValueOf(p.sets[0]) == std::stod(p.sets[0].substr(2)));
}

TEST_CASE("a run's sets apply to its scenario: the default scenario with the run's values") {
  const auto dir = rths_test::TempDir("sweep_spec");
  const fs::path spec_file = dir / "s.toml";
  {
    std::ofstream(spec_file) << "[sweep]\nbase = \"" << (fs::path(RTHS_SOURCE_DIR) / "scenarios" / "default.toml").string()
                             << "\"\n[grid]\n\"controller.kind\" = [\"none\", \"ff\"]\n\"run.duration_s\" = [0.5]\n";
  }
  const auto spec = rths::sweep::LoadSpec(spec_file.string());
  const auto p = PointOf(spec, 0);
  const auto s = rths::scenario::LoadScenario(p.scenario, p.sets);
  CHECK(s.run.duration_s == 0.5);
  CHECK(s.steps() == 1000);
}

TEST_CASE("bad SPECs are refused naming the file, the key and what is allowed") {
  const std::string f = "/x/bad.toml";
  auto refused = [&](const std::string& text, const std::string& needle) {
    CAPTURE(text);
    try {
      ParseSpec(text, f);
      FAIL("accepted");
    } catch (const rths::Error& e) {
      const std::string what = e.what();
      CAPTURE(what);
      CHECK(what.find(f) != std::string::npos);
      CHECK(what.find(needle) != std::string::npos);
    }
  };
  refused("", "needs a [sweep] table");
  refused("[sweep]\nseed = 1\n", "sweep.base");
  refused("[sweep]\nbase = \"b\"\nspeed = 1\n", "unknown key; allowed: name, base, seed, draws, record");
  refused("[sweep]\nbase = \"b\"\n[grids]\n", "unknown table");
  refused("[sweep]\nbase = \"b\"\n[grid]\n\"a.b\" = []\n", "non-empty array");
  refused("[sweep]\nbase = \"b\"\n[grid]\n\"a.b\" = [[1, \"x\"]]\n", "values must be");  // [[1]]: one array level
  refused("[sweep]\nbase = \"b\"\n[grid]\n\"a.b\" = [[]]\n", "values must be");
  refused("[sweep]\nbase = \"b\"\n[grid]\n\"a.b\" = [[[1]]]\n", "values must be");
  refused("[sweep]\nbase = \"b\"\n[grid]\n\"a.b[0]\" = [1.0]\n", "may be drawn in [draw]");
  refused("[sweep]\nbase = \"b\"\n[set]\n\"a.b[0]\" = 1.0\n", "may be drawn in [draw]");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a.b[x]\" = { dist = \"seed\" }\n", "KEY[i], i an integer");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a.b[1\" = { dist = \"seed\" }\n", "KEY[i], i an integer");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a[0]\" = { dist = \"seed\" }\n\"a[00]\" = { dist = \"seed\" }\n",
          "more than one");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a\" = { dist = \"beta\" }\n", "allowed \"normal\"");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a\" = { dist = \"normal\", mean = 0.0, std = -1.0 }\n",
          "out of range [0, inf)");
  refused("[sweep]\nbase = \"b\"\ndraws = 2\n[draw]\n\"a\" = { dist = \"uniform\", lo = 1.0, hi = 1.0 }\n",
          "lo < hi");
  refused("[sweep]\nbase = \"b\"\n[draw]\n\"a\" = { dist = \"seed\" }\n", "sweep.draws >= 1");
  refused("[sweep]\nbase = \"b\"\ndraws = 3\n", "needs a [draw] table");
  refused("[sweep]\nbase = \"b\"\n[cases]\nfiles = [\"c\"]\n", "not both");
  // [slurm] setup: shell lines, one per entry.
  refused("[sweep]\nbase = \"b\"\n[slurm]\nsetup = \"module load gcc\"\n", "slurm.setup: must be an array of shell lines");
  refused("[sweep]\nbase = \"b\"\n[slurm]\nsetup = [\"module load gcc\", 12]\n", "slurm.setup[1]: must be a string");
  refused("[sweep]\nbase = \"b\"\n[slurm]\nsetup = [\"module load gcc\\nrm -rf x\"]\n", "slurm.setup[0]: holds a newline");
  refused("[sweep]\nbase = \"b\"\n[slurm]\nsetup = [\"  \"]\n", "slurm.setup[0]: is empty");
  refused("[sweep]\nbase = \"b\"\ndraws = 100000\n[draw]\n\"a\" = { dist = \"seed\" }\n[grid]\n\"k\" = "
          "[1,2,3,4,5,6,7,8,9,10,11]\n\"l\" = [1,2,3,4,5,6,7,8,9,10]\n",
          "more than the");
}

TEST_CASE("[slurm] setup: the lines in order, as given") {
  const auto spec = ParseSpec("[sweep]\nbase = \"b\"\n[slurm]\nsetup = [\"module load gcc/12 cmake\", "
                              "\"source /etc/profile.d/modules.sh  # 'quotes' and \\\"more\\\"\"]\n",
                              "/x/s.toml");
  CHECK(spec.slurm.setup ==
        std::vector<std::string>{"module load gcc/12 cmake", "source /etc/profile.d/modules.sh  # 'quotes' and \"more\""});
}

TEST_CASE("the named draw benchmark_plant: the benchmark's perturbed plant and, with it, its numerical substructure") {
  const auto dir = rths_test::TempDir("sweep_bench_draw");
  const fs::path spec_file = dir / "s.toml";
  const fs::path cases = fs::path(RTHS_SOURCE_DIR) / "scenarios" / "benchmark";
  std::ofstream(spec_file) << "[sweep]\nseed = 5\ndraws = 3\n[cases]\nfiles = [\"" << (cases / "case1_example.toml").string()
                           << "\", \"" << (cases / "case3_example.toml").string() << "\"]\n"
                           << "[draw]\n\"plant.benchmark\" = { dist = \"benchmark_plant\" }\n";
  const auto spec = rths::sweep::LoadSpec(spec_file.string());
  REQUIRE(spec.runs() == 6);
  CHECK(rths::sweep::DrawColumns(spec.draw[0]) ==
        std::vector<std::string>{"plant.benchmark.b1", "plant.benchmark.b2", "plant.benchmark.a3",
                                 "plant.benchmark.k_e_N_per_m"});
  const rths::models::BenchmarkPlantParams nominal;
  std::set<double> k_e;
  for (std::int64_t i = 0; i < spec.runs(); ++i) {
    const auto p = PointOf(spec, i);
    REQUIRE(p.sets.size() == 5);
    CHECK(p.sets[4] == "structure.subtract_specimen=true");
    const auto s = rths::scenario::LoadScenario(p.scenario, p.sets);
    const auto& b = s.plant.benchmark.params;
    k_e.insert(b.k_e_N_per_m);
    CHECK(b.b1 == ValueOf(p.sets[0]));
    CHECK(b.k_e_N_per_m == ValueOf(p.sets[3]));
    CHECK(b.b1 != nominal.b1);
    CHECK(b.gain == nominal.gain);  // only b1, b2, a3 and k_e are uncertain
    // Within about 4 sigma of the benchmark's uncertainty (b1 425 +- 3.3, k_e 1.19e6 +- 5e4 N/m).
    CHECK(std::abs(b.b1 - 425.0) < 4 * 3.3);
    CHECK(std::abs(b.k_e_N_per_m - 1.19e6) < 4 * 5e4);
    // The numerical substructure is the reference minus this plant's specimen at floor 1.
    const auto& st = s.structure;
    CHECK(st.matrices.K(0, 0) == doctest::Approx(st.reference.K(0, 0) - 1e-6 * b.k_e_N_per_m).epsilon(1e-14));
    CHECK(st.matrices.M(0, 0) == doctest::Approx(st.reference.M(0, 0) - 1e-6 * b.m_e_kg).epsilon(1e-14));
    CHECK(st.matrices.K(1, 1) == st.reference.K(1, 1));
    CHECK(st.matrices.iota(0) == doctest::Approx(st.reference.M(0, 0) / st.matrices.M(0, 0)).epsilon(1e-14));
  }
  CHECK(k_e.size() == 6);  // a plant of its own per run
  CHECK(PointOf(spec, 4).sets == PointOf(spec, 4).sets);
  // The key is the plant's table, nothing else.
  CHECK_THROWS_WITH_AS(ParseSpec("[sweep]\nbase = \"x.toml\"\ndraws = 1\n[draw]\n\"plant.gain\" = { dist = \"benchmark_plant\" }\n",
                                 "s.toml"),
                       doctest::Contains("plant.benchmark"), rths::Error);
}

TEST_CASE("structure.subtract_specimen: the nominal plant's numerical substructure is the repository's file") {
  const fs::path file = fs::path(RTHS_SOURCE_DIR) / "scenarios" / "benchmark" / "case2_example.toml";
  const auto with_file = rths::scenario::LoadScenario(file.string());
  const auto subtracted = rths::scenario::LoadScenario(file.string(), {"structure.subtract_specimen=true"});
  const auto& a = with_file.structure.matrices;
  const auto& b = subtracted.structure.matrices;
  CHECK((a.M - b.M).cwiseAbs().maxCoeff() <= 1e-15 * a.M.cwiseAbs().maxCoeff());
  CHECK((a.K - b.K).cwiseAbs().maxCoeff() <= 1e-15 * a.K.cwiseAbs().maxCoeff());
  CHECK((a.C - b.C).cwiseAbs().maxCoeff() <= 1e-14 * a.C.cwiseAbs().maxCoeff());
  CHECK((a.IotaOrOnes() - b.IotaOrOnes()).cwiseAbs().maxCoeff() <= 1e-14);
  // Refused where there is no benchmark specimen to subtract.
  const std::string e = rths_test::ParseError("[structure]\nsubtract_specimen = true\n");
  CHECK(e.find("structure.subtract_specimen") != std::string::npos);
}

namespace {

/// The benchmark's case 1 (its example PI C(s) = (2 s + 95)/s: feedback num = [2.0, 95.0]).
const fs::path kCase1 = fs::path(RTHS_SOURCE_DIR) / "scenarios" / "benchmark" / "case1_example.toml";

rths::sweep::Spec SpecFile(const std::string& name, const std::string& tables) {
  const fs::path file = rths_test::TempDir(name) / "s.toml";
  std::ofstream(file) << "[sweep]\nbase = \"" << kCase1.string() << "\"\nseed = 4\n" << tables;
  return rths::sweep::LoadSpec(file.string());
}

}  // namespace

TEST_CASE("a grid of transfer function coefficients: array levels, as --set takes them, named by their text") {
  const auto spec = SpecFile("sweep_array_grid", "[grid]\n\"controller.lti.feedback.num\" = [[2, 95], [3.0, 120.5]]\n"
                                                 "[set]\n\"controller.lti.feedback.den\" = [1.0, 0.0]\n");
  REQUIRE(spec.runs() == 2);
  CHECK(spec.grid[0].values == std::vector<std::string>{"[2, 95]", "[3.0, 120.5]"});
  CHECK(spec.fixed[0].second == "[1.0, 0.0]");
  const auto p1 = PointOf(spec, 1);
  CHECK(p1.sets.back() == "controller.lti.feedback.num=[3.0, 120.5]");
  const auto s = rths::scenario::LoadScenario(p1.scenario, rths::sweep::ScenarioSets(p1));
  CHECK(s.controller.lti.feedback.num == std::vector<double>{3.0, 120.5});
  CHECK(s.controller.lti.feedback.den == std::vector<double>{1.0, 0.0});
  // The same value through --set: the same scenario, hash included.
  const auto by_set = rths::scenario::LoadScenario(kCase1.string(), {"controller.lti.feedback.den=[1.0, 0.0]",
                                                                     "controller.lti.feedback.num=[3.0, 120.5]"});
  CHECK(by_set.sha256 == s.sha256);
}

TEST_CASE("[draw] of one element of an array: the rest of the array is the scenario's, [set]'s or the grid's") {
  const auto spec = SpecFile("sweep_element_draw", "draws = 50\n[draw]\n"
                                                   "\"controller.lti.feedback.num[0]\" = { dist = \"normal\", mean = 2.0, std = 0.2 }\n"
                                                   "\"controller.lti.feedback.num[1]\" = { dist = \"uniform\", lo = 80.0, hi = 110.0 }\n");
  REQUIRE(spec.runs() == 50);
  CHECK(rths::sweep::DrawColumns(spec.draw[0]) == std::vector<std::string>{"controller.lti.feedback.num[0]"});
  double sum = 0;
  std::set<double> kp;
  for (std::int64_t i = 0; i < spec.runs(); ++i) {
    const auto p = PointOf(spec, i);
    REQUIRE(p.sets.size() == 2);
    REQUIRE(p.sets[0].rfind("controller.lti.feedback.num[0]=", 0) == 0);
    const double k_p = ValueOf(p.sets[0]), k_i = ValueOf(p.sets[1]);
    const auto s = rths::scenario::LoadScenario(p.scenario, rths::sweep::ScenarioSets(p));
    CHECK(s.controller.lti.feedback.num == std::vector<double>{k_p, k_i});  // both drawn, bit for bit
    CHECK(s.controller.lti.feedback.den == std::vector<double>{1.0, 0.0});  // the case's
    CHECK(k_i >= 80.0);
    CHECK(k_i < 110.0);
    sum += k_p;
    kp.insert(k_p);
  }
  CHECK(kp.size() == 50);
  CHECK(std::abs(sum / 50 - 2.0) < 5 * 0.2 / std::sqrt(50.0));
  // One element drawn: the other is the case's value, or [set]'s.
  const auto one = SpecFile("sweep_element_one", "draws = 2\n[draw]\n"
                                                 "\"controller.lti.feedback.num[0]\" = { dist = \"normal\", mean = 2.0, std = 0.2 }\n");
  const auto p = PointOf(one, 1);
  const std::string drawn = p.sets[0].substr(p.sets[0].find('=') + 1);
  CHECK(rths::sweep::ScenarioSets(p) == std::vector<std::string>{"controller.lti.feedback.num=[" + drawn + ", 95.0]"});
  const auto with_set = SpecFile("sweep_element_set", "draws = 2\n[set]\n\"controller.lti.feedback.num\" = [3, 120]\n"
                                                      "[draw]\n\"controller.lti.feedback.num[0]\" = { dist = \"normal\", mean = 2.0, std = 0.2 }\n");
  const auto q = PointOf(with_set, 1);
  CHECK(q.sets[1] == p.sets[0]);  // the same stream: (seed, index, key)
  const auto s = rths::scenario::LoadScenario(q.scenario, rths::sweep::ScenarioSets(q));
  CHECK(s.controller.lti.feedback.num == std::vector<double>{ValueOf(p.sets[0]), 120.0});
}

TEST_CASE("a drawn element beyond its array is refused naming the SPEC file, the key and the allowed range") {
  const auto message = [](const std::string& name, const std::string& tables) {
    try {
      SpecFile(name, tables);
    } catch (const rths::Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string draw = "draws = 2\n[draw]\n\"controller.lti.feedback.num[2]\" = { dist = \"normal\", mean = 2.0, std = 0.2 }\n";
  std::string e = message("sweep_element_range", draw);
  CHECK(e.find("sweep_element_range/s.toml: draw.\"controller.lti.feedback.num[2]\"") != std::string::npos);
  CHECK(e.find("index 2 is out of range [0, 2)") != std::string::npos);
  CHECK(e.find("[2.0, 95.0] in case1_example.toml") != std::string::npos);
  // Checked against each level of a grid of the same array.
  e = message("sweep_element_grid", draw + "[grid]\n\"controller.lti.feedback.num\" = [[1, 2, 3], [1, 2]]\n");
  CHECK(e.find("index 2 is out of range [0, 2)") != std::string::npos);
  CHECK(e.find("(grid controller.lti.feedback.num=[1, 2])") != std::string::npos);
  CHECK(message("sweep_element_grid_ok", draw + "[grid]\n\"controller.lti.feedback.num\" = [[1, 2, 3], [4, 5, 6]]\n") ==
        "accepted");
  // Not an array.
  e = message("sweep_element_scalar",
              "draws = 2\n[draw]\n\"run.duration_s[0]\" = { dist = \"uniform\", lo = 1.0, hi = 2.0 }\n");
  CHECK(e.find("sweep_element_scalar/s.toml: draw.\"run.duration_s[0]\"") != std::string::npos);
  CHECK(e.find("is not an array") != std::string::npos);
}
