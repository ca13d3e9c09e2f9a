// Clipped-optimal semiactive control (Dyke et al. 1996; control/clipped_optimal.h) on the
// 9-story building: the nominal LQG is stable, the clipping law is right, and under El Centro
// it reduces the peak absolute accelerations against both passive cases.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "control/clipped_optimal.h"
#include "io/run_log.h"
#include "models/structure_file.h"
#include "run_support.h"
#include "test_support.h"

using namespace rths_test;

namespace {
rths::models::LinearStructure NineStory() {
  const auto m = rths::models::LoadStructureFile(std::string(RTHS_SOURCE_DIR) + "/data/buildings/ohtori9_ns.txt");
  return rths::models::LinearStructure::Make(m.M, m.C, m.K, 0, 18.0);
}
}  // namespace

TEST_CASE("the nominal H2/LQG is stable and the clipping law follows (f_c - f) f > 0") {
  const auto design = rths::control::DesignClippedOptimal(NineStory(), 0.0005, {});
  CHECK(design.K.size() == 18);
  for (const auto& p : design.regulator_poles) CHECK(std::abs(p) < 1.0);
  for (const auto& p : design.estimator_poles) CHECK(std::abs(p) < 1.0);
  rths::control::ClippedOptimal law(design);
  std::vector<double> a(9, 0.0);
  // At rest f_c = 0: the law asks for 0 A whatever the force (H(0) = 0 and (0 - f) f <= 0).
  CHECK(law.Step(0, a.data(), 0.0, 5.0) == 0.0);
  CHECK(law.Step(1, a.data(), 0.0, 0.0) == 0.0);
  // A first-floor acceleration makes the controller ask for a force; the law's four cases.
  a[0] = 2000.0;
  law.Step(2, a.data(), 0.0, 0.0);
  const double fc = law.desired_force_kN();
  REQUIRE(fc != 0.0);
  std::vector<double> zero(9, 0.0);
  const double same_sign_smaller = 0.5 * fc, same_sign_larger = 2.0 * fc, opposite = -fc;
  // Replay the same inputs so f_c is the same, with different measured forces.
  auto current_for = [&](double f) {
    rths::control::ClippedOptimal l(design);
    l.Step(1, zero.data(), 0.0, 0.0);
    return l.Step(2, a.data(), 0.0, f);
  };
  CHECK(current_for(same_sign_smaller) == 2.5);  // |f| < |f_c|, same sign: more force wanted
  CHECK(current_for(same_sign_larger) == 0.0);   // the damper already gives more than wanted
  CHECK(current_for(opposite) == 0.0);           // force of the wrong sign: let it go
}

TEST_CASE("9-story under El Centro: clipped-optimal reduces peak accelerations against passive") {
  auto peak_abs_acc = [](const std::string& mode, const fs::path& dir) {
    const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 12.0
[structure]
kind = "file"
file = ")" + std::string(RTHS_SOURCE_DIR) + R"(/data/buildings/ohtori9_ns.txt"
actuator_dof = 1
specimen_count = 18.0
[structure.ground]
kind = "file"
file = ")" + std::string(RTHS_SOURCE_DIR) + R"(/data/ground_motion/elcentro_1940_ns_g.txt"
file_dt_s = 0.02
scale = 4903.325
[controller]
kind = "ff"
[semiactive]
mode = ")" + mode + "\"\n").string());
    REQUIRE(RunMemq({s}, dir).code == 0);
    const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
    double peak = 0.0;
    for (std::int64_t k = 0; k < log.CompleteSteps(); ++k) {
      for (double a : log.desired[k].abs_acc_mm_s2) peak = std::max(peak, std::abs(a));
    }
    MESSAGE(mode << ": peak absolute acceleration " << peak / 1000.0 << " m/s^2");
    return peak;
  };
  const double off = peak_abs_acc("passive_off", TempDir("co_off"));
  const double on = peak_abs_acc("passive_on", TempDir("co_on"));
  const double clipped = peak_abs_acc("clipped_optimal", TempDir("co_clipped"));
  CHECK(clipped < off);
  CHECK(clipped < on);
}
