// The maRTHS benchmark through the lockstep (marths.enabled; participants/marths_participants.h): two
// actuators' targets, commands and strokes in the per-step messages, the integrator answering
// desired_t k from measured_t k. Every number is held to the in-process loop of studies/marths_loop.h,
// configured here from the data files directly (not through the participants' helpers), and udpm runs
// (a process per participant) log the memq run's payloads bit for bit, also with lost datagrams repaired.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/exit_code.h"
#include "ident/design_model.h"
#include "io/run_log.h"
#include "models/marths_files.h"
#include "models/marths_structure.h"
#include "participants/marths_run.h"
#include "participants/replay.h"
#include "scenario/scenario.h"
#include "signal/history.h"
#include "signal/random.h"
#include "studies/marths_loop.h"

#include "run_support.h"
#include "udpm_support.h"

namespace fs = std::filesystem;
namespace mm = rths::models::marths;
using rths::studies::MarthsCompensator;
using rths_test::RunCli;
using rths_test::RunMemq;
using rths_test::TempDir;

namespace {

const std::string kData = std::string(RTHS_SOURCE_DIR) + "/data/marths/";
const std::string kScenario = std::string(RTHS_SOURCE_DIR) + "/scenarios/marths/elcentro_none.toml";
constexpr double kSeconds = 6.0;  // the strong motion begins within the record's first seconds

/// The shipped scenario, shortened, with `sets`; model_1/2 resolved as `rths run` does.
rths::scenario::Scenario Scenario(std::vector<std::string> sets) {
  sets.push_back(fmt::format("run.duration_s={}", kSeconds));
  rths::scenario::Scenario s = rths::scenario::LoadScenario(kScenario, sets);
  rths::ident::ResolveDesignModel(&s);
  return s;
}

/// The same run as the in-process loop, its configuration made from the data files here.
rths::studies::MarthsLoopResult Loop(MarthsCompensator kind, std::size_t n, const mm::PlantZpk& plant,
                                     std::uint64_t noise_seed, bool identical_noise) {
  rths::studies::MarthsLoopConfig c;
  c.K_ref = mm::ReadMatrixCsv(kData + "reference_K_N_per_m.csv");
  c.M_ref = mm::ReadMatrixCsv(kData + "reference_M_kg.csv");
  const auto rec = rths::signal::ReadHistoryFile(kData + "elcentro_m_s2.txt", 0.0);
  c.ag_m_s2 = rths::signal::ResampleHistory(rec, 0.0, 0.4, c.dt_s, n, 0.0);
  c.plant = plant;
  c.rig.noise_mm = mm::SensorNoiseMm(c.dt_s);
  c.rig.noise_seed = noise_seed;
  c.rig.identical_noise = identical_noise;
  c.compensators.kind = kind;
  const auto p = mm::ReadRodeacParameters(kData + "rodeac_initial_parameters.txt");
  const auto models = rths::ident::MarthsDesignModels(mm::NominalPlantZpk(), c.dt_s);
  for (int i = 0; i < 2; ++i) {
    c.compensators.rodeac[i] = rths::control::MakeRodeacDesign(p.theta0[i], p.P0[i], 1.0 / c.dt_s);
    c.compensators.per_actuator[i].model = models[i];
  }
  return rths::studies::RunMarthsLoop(c);
}

/// The lockstep run's log equals the loop's signals sample for sample (targets and strokes bit for
/// bit), and its score the loop's.
void CheckSame(const rths::io::RunLog& log, const rths::scenario::Scenario& s,
               const rths::studies::MarthsLoopResult& loop) {
  const std::int64_t n = log.CompleteSteps();
  REQUIRE(n == static_cast<std::int64_t>(loop.signals.xa1_t.size()));
  std::int64_t differ = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const auto& d = log.desired[i];
    const auto& m = log.measured[i];
    REQUIRE(d.n_act == 2);
    REQUIRE(m.n_act == 2);
    REQUIRE(m.n_iface == 3);
    differ += d.r_act_mm[0] != loop.signals.xa1_t[i] || d.r_act_mm[1] != loop.signals.xa2_t[i] ||
              m.y_act_mm[0] != loop.signals.xa1_m[i] || m.y_act_mm[1] != loop.signals.xa2_m[i];
  }
  CHECK(differ == 0);
  const auto score = rths::participants::MarthsScoreOfRun(log, s);
  const auto a = score.j.Items(), b = loop.j.Items();
  for (std::size_t i = 0; i < a.size(); ++i) {
    CAPTURE(a[i].first);
    CHECK(a[i].second == doctest::Approx(b[i].second).epsilon(1e-9));
  }
  CHECK(score.max_volts[0] == loop.max_volts[0]);
  CHECK(score.max_volts[1] == loop.max_volts[1]);
  CHECK(score.realizable == !loop.saturated);
}

}  // namespace

TEST_CASE("maRTHS through the lockstep (memq) = the in-process loop, every compensator, noise on") {
  for (MarthsCompensator kind : {MarthsCompensator::kNone, MarthsCompensator::kRodeac, MarthsCompensator::kFf,
                                 MarthsCompensator::kFfLqg, MarthsCompensator::kMimoFf}) {
    const std::string name(NameOf(rths::control::kMarthsCompensatorNames, kind));
    CAPTURE(name);
    const auto s = Scenario({"marths.compensator=" + name});
    const fs::path dir = TempDir("marths_" + name);
    const auto r = RunMemq({s}, dir);
    CAPTURE(r.errors.back());
    REQUIRE(r.code == 0);
    const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
    REQUIRE(log.CompleteSteps() == s.steps());
    CheckSame(log, s, Loop(kind, static_cast<std::size_t>(s.steps()), mm::NominalPlantZpk(), 123, true));
  }
}

TEST_CASE("maRTHS lockstep: a perturbed plant and independent noise, as the study draws them") {
  // rths reproduce marths's perturbed_3: the third plant drawn from seed 47, noise seed 123 + 3.
  const auto s = Scenario({"marths.compensator=mimo_ff", "marths.perturbed_plant=3", "marths.noise_seed=126",
                           "marths.identical_noise=false"});
  const fs::path dir = TempDir("marths_perturbed");
  REQUIRE(RunMemq({s}, dir).code == 0);
  rths::signal::GaussianState g = rths::signal::MakeGaussian(47);
  mm::PlantZpk plant;
  for (int i = 0; i < 3; ++i) plant = mm::PerturbedPlantZpk(mm::NominalPlantZpk(), &g);
  CheckSame(rths::io::ReadRunLog((dir / "log.lcm").string()), s,
            Loop(MarthsCompensator::kMimoFf, static_cast<std::size_t>(s.steps()), plant, 126, false));
}

TEST_CASE("maRTHS lockstep: udpm gives memq's log bit for bit, one process per participant, also with 5 % of "
          "datagrams lost; summary.json holds marths_criteria") {
  if (!rths_test::UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto s = Scenario({"marths.compensator=rodeac"});
  const fs::path memq = TempDir("marths_memq");
  REQUIRE(RunMemq({s}, memq).code == 0);
  const std::string digest = rths::io::PayloadDigest(rths::io::ReadRunLog((memq / "log.lcm").string()));
  const std::string args = kScenario + fmt::format(" --set run.duration_s={} --set marths.compensator=rodeac", kSeconds);
  for (const std::string extra : {" --transport udpm", " --transport udpm --set faults.drop=0.05"}) {
    CAPTURE(extra);
    const fs::path out = TempDir("marths_cli") / "run";
    std::string output;
    REQUIRE(RunCli(args + extra + " --out " + out.string(), &output) == 0);
    CAPTURE(output);
    CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((out / "log.lcm").string())) == digest);
    CHECK(output.find("maRTHS") != std::string::npos);
    const auto summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
    REQUIRE(summary.contains("marths_criteria"));
    CHECK(summary["marths_criteria"].size() == 22);
    for (const char* key : {"J1_1_ms", "J2_1_pct", "J5_TH_pct", "J10_TH3_pct"}) {
      CAPTURE(key);
      CHECK(summary["marths_criteria"].contains(key));
    }
    CHECK(summary["marths_criteria"]["J2_1_pct"].get<double>() > 0.0);
    CHECK(summary["marths_realizable"]["realizable"].get<bool>());
    CHECK(summary["marths_realizable"]["max_volts"].size() == 2);
    if (extra.find("drop") != std::string::npos) CHECK(summary["link"]["rerequests"].get<std::int64_t>() > 0);
  }
}

TEST_CASE("maRTHS lockstep: the safety monitor watches both actuators and names the one that tripped") {
  // Without compensation the second actuator's tracking error is the larger in the first 6 s
  // (0.171 mm against 0.130 mm): a limit between the two is left by actuator 2 alone.
  const auto free_run = Scenario({"marths.compensator=none"});
  const fs::path free_dir = TempDir("marths_safety_free");
  REQUIRE(RunMemq({free_run}, free_dir).code == 0);
  const auto free_log = rths::io::ReadRunLog((free_dir / "log.lcm").string());
  const double limit_mm = 0.15;
  std::int64_t first = -1;
  int which = 0;
  double peak[2] = {0.0, 0.0};
  for (std::int64_t k = 0; k < free_run.steps(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    for (int a = 0; a < 2; ++a) {
      const double e = std::abs(free_log.desired[i].r_act_mm[a] - free_log.measured[i].y_act_mm[a]);
      peak[a] = std::max(peak[a], e);
      if (e > limit_mm && first < 0) {
        first = k;
        which = a + 1;
      }
    }
  }
  CAPTURE(peak[0]);
  CAPTURE(peak[1]);
  REQUIRE(peak[0] < limit_mm);  // actuator 1 alone would never trip
  REQUIRE(first >= 0);
  CHECK(which == 2);

  const auto s = Scenario({"marths.compensator=none", fmt::format("safety.max_error_mm={}", limit_mm)});
  const fs::path dir = TempDir("marths_safety");
  const auto r = RunMemq({s}, dir);
  CHECK(r.code == rths::kExitSafety);
  const std::string& why = r.errors.back();
  CAPTURE(why);
  CHECK(why.find(fmt::format("safety: step {} ", first)) == 0);
  CHECK(why.find("actuator 2: tracking error |r - y|") != std::string::npos);
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  CHECK(log.CompleteSteps() == first + 1);  // the log is whole up to the step that tripped
  CHECK(log.AbortReason().find("actuator 2") != std::string::npos);
}

TEST_CASE("maRTHS lockstep: a lab's own model of the frame (the benchmark's, its DOFs renumbered, from files) "
          "gives the benchmark's run") {
  // The reference matrices with their 29 DOFs in a random order, written as a lab would export
  // them, and the interface, story and ground DOFs declared in that order.
  const Eigen::MatrixXd K = mm::ReadMatrixCsv(kData + "reference_K_N_per_m.csv");
  const Eigen::MatrixXd M = mm::ReadMatrixCsv(kData + "reference_M_kg.csv");
  std::vector<int> to(29);
  for (int i = 0; i < 29; ++i) to[static_cast<std::size_t>(i)] = i;
  std::mt19937_64 gen(29);
  std::shuffle(to.begin(), to.end(), gen);  // old DOF i (0-based) is new DOF to[i]
  const fs::path dir = TempDir("marths_renumbered");
  auto write = [&](const Eigen::MatrixXd& A, const fs::path& file) {
    Eigen::MatrixXd B(29, 29);
    for (int i = 0; i < 29; ++i) {
      for (int j = 0; j < 29; ++j) B(to[static_cast<std::size_t>(i)], to[static_cast<std::size_t>(j)]) = A(i, j);
    }
    std::ofstream out(file);
    for (int i = 0; i < 29; ++i) {
      for (int j = 0; j < 29; ++j) out << fmt::format("{}{:.17g}", j ? "," : "", B(i, j));
      out << "\n";
    }
  };
  write(K, dir / "K.csv");
  write(M, dir / "M.csv");
  auto renumbered = [&](auto dofs) {
    std::string list = "[";
    for (std::size_t i = 0; i < dofs.size(); ++i) list += fmt::format("{}{}", i ? ", " : "", to[static_cast<std::size_t>(dofs[i] - 1)] + 1);
    return list + "]";
  };
  const mm::FrameDofs bmk;
  const auto s = Scenario({"marths.compensator=rodeac", "marths.reference_k_file=" + (dir / "K.csv").string(),
                           "marths.reference_m_file=" + (dir / "M.csv").string(),
                           "marths.interface_dofs=" + renumbered(bmk.interface),
                           "marths.story_dofs=" + renumbered(bmk.stories),
                           "marths.ground_dofs=" + renumbered(bmk.ground)});
  CHECK(s.marths.dofs.x() == to[26] + 1);
  const auto base = Scenario({"marths.compensator=rodeac"});
  fs::create_directories(dir / "lab");
  fs::create_directories(dir / "bmk");
  REQUIRE(RunMemq({s}, dir / "lab").code == 0);
  REQUIRE(RunMemq({base}, dir / "bmk").code == 0);
  const auto lab = rths::io::ReadRunLog((dir / "lab" / "log.lcm").string());
  const auto ref = rths::io::ReadRunLog((dir / "bmk" / "log.lcm").string());
  REQUIRE(lab.CompleteSteps() == ref.CompleteSteps());
  double worst_target = 0.0, worst_dof = 0.0, peak = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(lab.CompleteSteps()); ++k) {
    for (int a = 0; a < 2; ++a) {
      worst_target = std::max(worst_target, std::abs(lab.desired[k].r_act_mm[a] - ref.desired[k].r_act_mm[a]));
      peak = std::max(peak, std::abs(ref.desired[k].r_act_mm[a]));
    }
    for (int i = 0; i < 29; ++i) {  // the lab's DOF to[i] is the benchmark's DOF i
      worst_dof = std::max(worst_dof, std::abs(lab.desired[k].x_mm[to[static_cast<std::size_t>(i)]] -
                                               ref.desired[k].x_mm[static_cast<std::size_t>(i)]));
    }
  }
  MESSAGE("renumbered frame: targets within ", worst_target, " mm of the benchmark's (peak ", peak,
          " mm), every DOF within ", worst_dof);
  CHECK(peak > 0.1);
  CHECK(worst_target < 1e-9 * peak);
  CHECK(worst_dof < 1e-9);
  const auto a = rths::participants::MarthsScoreOfRun(lab, s).j.Items();
  const auto b = rths::participants::MarthsScoreOfRun(ref, base).j.Items();
  for (std::size_t i = 0; i < a.size(); ++i) {
    CAPTURE(a[i].first);
    CHECK(a[i].second == doctest::Approx(b[i].second).epsilon(1e-8));
  }
}

TEST_CASE("maRTHS scenarios: bad input is refused naming the key") {
  const fs::path dir = TempDir("marths_bad");
  std::string output;
  // The ideal plant answers desired_t k: a cycle with the integrator's same-sample row.
  CHECK(RunCli(kScenario + " --set plant.kind=ideal --out " + (dir / "a").string(), &output) != 0);
  CHECK(output.find("plant.kind") != std::string::npos);
  CHECK(RunCli(kScenario + " --set marths.ground_file=nowhere.txt --out " + (dir / "b").string(), &output) != 0);
  CHECK(output.find("marths.ground_file") != std::string::npos);
  CHECK(RunCli(kScenario + " --set marths.compensator=pid --out " + (dir / "c").string(), &output) != 0);
  CHECK(output.find("marths.compensator") != std::string::npos);
  CHECK(output.find("mimo_ff") != std::string::npos);  // the allowed names
  CHECK(!fs::exists(dir / "a" / "log.lcm"));
}

TEST_CASE("maRTHS replay: each role live, alone, reproduces the recording bit for bit") {
  // A live "same_sample" integrator needs measured_t k before desired_t k: the recorded plant answers
  // on command_t k-1 (its ordinary row), not on desired_t k (which would be a cycle).
  const auto s = Scenario({"marths.compensator=ff_lqg"});
  const fs::path rec = TempDir("marths_replay_record");
  REQUIRE(RunMemq({s}, rec).code == 0);
  const auto record = rths::io::ReadRunLog((rec / "log.lcm").string());
  for (const char* role : {"integrator", "controller", "plant", "semiactive"}) {
    CAPTURE(role);
    const fs::path out = TempDir(std::string("marths_replay_") + role);
    const auto outcomes = rths::participants::RunReplay(s, record, record.CompleteSteps(), {role}, 77, out.string());
    for (const auto& o : outcomes) {
      CAPTURE(o.message);
      CHECK(o.exit_code == 0);
    }
    CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((out / "log.lcm").string())) == rths::io::PayloadDigest(record));
  }
}
