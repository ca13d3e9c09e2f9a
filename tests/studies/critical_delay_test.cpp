// The critical-delay study of issue 44 (studies/critical_delay.h, studies/nonlinear_delay.h,
// docs/reproduce_nonlinear.md): the closed-form delay margin, the loop at zero delay, the linear
// SDOF's critical delay per integrator against the closed form, compensation raising it, the
// yielding structure's self-sustained oscillation, and `rths reproduce nonlinear --quick`.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "io/csv.h"
#include "models/structure_integrator.h"
#include "studies/nonlinear_delay.h"
#include "test_support.h"

using namespace rths::studies;
namespace fs = std::filesystem;
using rths::models::IntegratorConfig;
using rths::models::IntegratorKind;

namespace {

const rths::scenario::Scenario& Reference() {
  static const auto s =
      rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear/reference_sdof.toml");
  return s;
}

IntegratorConfig Kind(IntegratorKind k) {
  IntegratorConfig c;
  c.kind = k;
  return c;
}

/// The quick study's loop (8 s of El Centro, 8 s tail).
DelayLoop QuickLoop(bool yielding, IntegratorKind k, DelayCompensation c) {
  const auto set = NonlinearDelayDefaults(true);
  return ReferenceDelayLoop(Reference(), yielding, Kind(k), c, set.record_s, set.tail_s);
}

DelayMargin ReferenceMargin() {
  const SplitSdof s = QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kNone).sdof;
  return ContinuousDelayMargin(s.Mass_kN_s2_per_mm(), s.Damping_kN_s_per_mm(), s.NumericalStiffness_kN_per_mm(),
                               s.PhysicalStiffness_kN_per_mm());
}

}  // namespace

TEST_CASE("closed-form delay margin: a root on the imaginary axis, near c / k_e, none when k_e is too weak") {
  const double m = 0.02, c = 0.0251327, kn = 9.8696, ke = 9.8696;  // the reference split [kN, mm, s]
  const DelayMargin d = ContinuousDelayMargin(m, c, kn, ke);
  REQUIRE(d.exists);
  const double w = 2 * M_PI * d.crossing_hz;
  const std::complex<double> s(0.0, w);
  const std::complex<double> ch = m * s * s + c * s + kn + ke * std::exp(-s * d.tau_s);
  CHECK(std::abs(ch) < 1e-9 * ke);
  // With k_n = k_e the crossing is at w^2 = w_n^2 (1 - 4 zeta^2), zeta = 2 %.
  CHECK(d.crossing_hz == doctest::Approx(5.0 * std::sqrt(1 - 4 * 0.02 * 0.02)).epsilon(1e-6));
  CHECK(d.tau_s == doctest::Approx(c / ke).epsilon(0.01));
  CHECK(d.negative_damping_s == doctest::Approx(c / ke));
  // A spring weaker than the damping's force at every frequency never destabilises the loop.
  CHECK_FALSE(ContinuousDelayMargin(1.0, 10.0, 100.0, 1.0).exists);
  CHECK_THROWS_AS(ContinuousDelayMargin(0.0, c, kn, ke), rths::Error);
}

TEST_CASE("the split SDOF: validated, and at zero delay the loop is the whole SDOF") {
  SplitSdof bad;
  bad.physical_fraction = 1.0;
  CHECK_THROWS_WITH_AS(bad.Validate(), doctest::Contains("physical_fraction"), rths::Error);
  // Central difference evaluates R(x_k) and f_k = k_e x_k at the same x_k: the split at tau = 0 is
  // the SDOF with the whole spring, up to rounding.
  DelayLoop loop = QuickLoop(false, IntegratorKind::kCentralDifference, DelayCompensation::kNone);
  const DelayRun split = RunDelayLoop(loop, 0.0, 0.0);
  SplitSdof whole = loop.sdof;
  const auto b = rths::models::NonlinearBuilding::Make(
      {whole.mass_kg}, {[&] {
        rths::models::SpringParams p;
        p.k_kN_per_mm = whole.TotalStiffness_kN_per_mm();
        return p;
      }()},
      Eigen::MatrixXd::Constant(1, 1, whole.Damping_kN_s_per_mm()), 0, 0.0);
  auto ground = loop.ground_mm_s2;
  ground.resize(ground.size() + static_cast<std::size_t>(std::llround(loop.tail_s / loop.dt_s)), 0.0);
  const auto run = rths::models::Simulate(rths::models::StructureIntegrator::Make(b, loop.dt_s, loop.integrator), ground);
  CHECK(split.peak_mm == doctest::Approx(run.x_mm.cwiseAbs().maxCoeff()).epsilon(1e-9));
  CHECK(split.peak_mm > 5.0);  // the record moves it
  CHECK_FALSE(Unstable(split, DelaySearch{}));
  CHECK_THROWS_AS(RunDelayLoop(loop, -1e-3, 0.0), rths::Error);
}

TEST_CASE("linear SDOF: the critical delay of every integrator agrees with the closed form") {
  const DelayMargin exact = ReferenceMargin();
  DelaySearch search = NonlinearDelayDefaults(true).search;
  search.resolution_s = 1e-5;
  for (auto k : {IntegratorKind::kCentralDifference, IntegratorKind::kCr, IntegratorKind::kAlphaOs,
                 IntegratorKind::kNewmarkImplicit}) {
    CAPTURE(static_cast<int>(k));
    const DelayLoop loop = QuickLoop(false, k, DelayCompensation::kNone);
    const CriticalDelay cd = FindCriticalDelay(loop, search);
    REQUIRE(cd.found);
    CHECK(cd.unstable_s - cd.stable_s <= search.resolution_s);
    // newmark_implicit holds the measured force one sample late (integrator_newmark.h): one dt less.
    const double expected = exact.tau_s - (k == IntegratorKind::kNewmarkImplicit ? loop.dt_s : 0.0);
    CHECK(cd.tau_s == doctest::Approx(expected).epsilon(0.01));  // 1 % (25 us)
  }
}

TEST_CASE("compensation designed for the delay raises the critical delay; ff on the Taylor model is poly3") {
  const DelaySearch search = NonlinearDelayDefaults(true).search;
  const CriticalDelay none = FindCriticalDelay(QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kNone), search);
  const CriticalDelay poly3 = FindCriticalDelay(QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kPoly3), search);
  const CriticalDelay lead = FindCriticalDelay(QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kLead), search);
  const CriticalDelay ff = FindCriticalDelay(QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kFf), search);
  REQUIRE(none.found);
  CHECK(poly3.tau_s > 5 * none.tau_s);
  CHECK(lead.tau_s > 5 * none.tau_s);
  CHECK(std::abs(ff.tau_s - poly3.tau_s) <= search.resolution_s);
  // The Taylor model's inverse is 1 + tau s + (tau s)^2 / 2 + (tau s)^3 / 6.
  const auto m = TaylorDelayModel(0.01);
  CHECK(m.p + m.b == doctest::Approx(300.0));
  CHECK(m.p * m.b + m.c == doctest::Approx(6e4));
  CHECK(m.K == doctest::Approx(m.p * m.c));
  CHECK(m.K == doctest::Approx(6e6));
}

TEST_CASE("yielding SDOF: between the two criteria the delay sustains an oscillation the hysteresis bounds") {
  // At 6 ms (beyond the linear margin, 2.55 ms) the linear loop diverges; the Bouc-Wen loop settles
  // into a limit cycle after the record: neither decaying nor growing.
  DelayLoop y = QuickLoop(true, IntegratorKind::kCr, DelayCompensation::kNone);
  y.tail_s = 60.0;
  const DelayRun free = RunDelayLoop(y, 0.0, 0.0);
  const DelayRun r = RunDelayLoop(y, 6e-3, 10 * free.peak_mm);
  CHECK_FALSE(r.diverged);
  CHECK(r.tail_late_range_mm > 1.0);  // mm: not at rest
  CHECK(r.tail_late_range_mm == doctest::Approx(r.tail_early_range_mm).epsilon(0.01));
  CHECK(Verdict(r, DelaySearch{}) == "does not decay");
  DelayLoop lin = QuickLoop(false, IntegratorKind::kCr, DelayCompensation::kNone);
  lin.tail_s = 60.0;
  const DelayRun lin_free = RunDelayLoop(lin, 0.0, 0.0);
  CHECK(RunDelayLoop(lin, 6e-3, 10 * lin_free.peak_mm).diverged);
}

TEST_CASE("rths reproduce nonlinear --quick writes its table, its Markdown and its figure") {
  rths_test::RequireBuilt("rths-reproduce");
  const fs::path out = rths_test::TempDir("reproduce_nonlinear");
  const std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-reproduce nonlinear --quick --out " + out.string() +
                          " > " + (out.parent_path() / "nonlinear.txt").string() + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const auto rows = rths::io::ReadCsvFile(out / "critical_delay.csv");
  REQUIRE(rows.size() == 1 + 4 * 2 * NonlinearDelayColumns().size());
  CHECK(rows[0][0] == "integrator");
  CHECK(rows[0][3] == "tau_cr_ms");
  int linear_checked = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i][1] != "linear" || rows[i][2] != "none" || rows[i][0] == "newmark_implicit") continue;
    CHECK(std::stod(rows[i][3]) == doctest::Approx(std::stod(rows[i][11])).epsilon(0.02));
    ++linear_checked;
  }
  CHECK(linear_checked == 3);
  const std::string md = rths_test::Slurp(out / "critical_delay.md");
  CHECK(md.find("| cr | yielding |") != std::string::npos);
  rths_test::RequireTool("gnuplot", "gnuplot-nox");
  CHECK(fs::file_size(out / "critical_delay.png") > 1000);
  // No lockstep runs: --set is refused, not silently ignored.
  const std::string set = std::string(RTHS_BIN_DIR) + "/rths-reproduce nonlinear --quick --set run.dt_s=0.001 --out " +
                          (out.parent_path() / "nonlinear_set").string() + " > /dev/null 2>&1";
  const int status = std::system(set.c_str());
  CHECK((WIFEXITED(status) ? WEXITSTATUS(status) : -1) == 2);
}
