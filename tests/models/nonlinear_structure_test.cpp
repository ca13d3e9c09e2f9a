// Hysteretic story springs (models/story_spring.h), the nonlinear shear building and its
// integrators (models/structure_integrator.h): closed forms, the linear degenerate case against
// today's central difference, stability, and allocation-free steps.
#include <cmath>
#include <numbers>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "alloc_counter.h"
#include "core/error.h"
#include "models/benchmark_structures.h"
#include "models/equivalent_shear.h"
#include "models/nonlinear_building.h"
#include "models/story_spring.h"
#include "models/structure.h"
#include "models/structure_file.h"
#include "models/structure_integrator.h"

using namespace rths::models;

namespace {

constexpr double kPi = std::numbers::pi;

SpringParams BoucWen(double k, double alpha, double x_y) {
  SpringParams p;
  p.kind = SpringKind::kBoucWen;
  p.k_kN_per_mm = k, p.alpha = alpha, p.x_y_mm = x_y;
  p.n = 1.0, p.beta = 0.5, p.gamma = 0.5;
  return p;
}

SpringParams Bilinear(double k, double b, double f_y) {
  SpringParams p;
  p.kind = SpringKind::kBilinear;
  p.k_kN_per_mm = k, p.b = b, p.f_y_kN = f_y;
  return p;
}

SpringParams Linear(double k) {
  SpringParams p;
  p.k_kN_per_mm = k;
  return p;
}

// The Ohtori 9-story masses and story stiffnesses (data/buildings/ohtori9_ns.txt).
const std::vector<double> kMasses9 = {505000, 494500, 494500, 494500, 494500, 494500, 494500, 494500, 535000};
const std::vector<double> kStories9 = {65.0, 295.6, 355.9, 191.9, 193.3, 141.9, 157.9, 80.2, 194.4};

std::vector<double> Chirp(double dt, int n, double amp_mm_s2) {  // a ground record with content up to 20 Hz
  std::vector<double> ag(n);
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    ag[k] = amp_mm_s2 * std::sin(2 * kPi * (0.5 + 2.0 * t) * t) * std::exp(-0.2 * t);
  }
  return ag;
}

}  // namespace

TEST_CASE("Bouc-Wen virgin loading follows z = x_y (1 - exp(-u / x_y)) and its dissipated energy") {
  const SpringParams p = BoucWen(20.0, 0.1, 4.0);
  const auto z_exact = [&](double u) { return 4.0 * (1.0 - std::exp(-u / 4.0)); };
  // E_h = (1 - alpha) k (x_y (u - z) - z^2 / 2)
  const auto e_exact = [&](double u) {
    const double z = z_exact(u);
    return 0.9 * 20.0 * (4.0 * (u - z) - 0.5 * z * z);
  };
  // In one increment of 3 x_y (120 RK4 sub-steps) and in 600 increments of 0.02 mm.
  const SpringTrial one = EvaluateSpring(p, SpringState{}, 12.0);
  MESSAGE("one increment of 12 mm: z error " << one.state.z_mm - z_exact(12.0) << " mm, E_h error "
                                             << one.state.energy_kN_mm - e_exact(12.0) << " kN mm");
  CHECK(std::abs(one.state.z_mm - z_exact(12.0)) < 1e-9 * 4.0);
  CHECK(std::abs(one.state.energy_kN_mm - e_exact(12.0)) < 1e-8 * e_exact(12.0));
  CHECK(one.force_kN == doctest::Approx(0.1 * 20 * 12 + 0.9 * 20 * z_exact(12.0)).epsilon(1e-9));
  CHECK(one.tangent_kN_per_mm == doctest::Approx(20 * (0.1 + 0.9 * std::exp(-3.0))).epsilon(1e-8));
  SpringState s;
  double max_err = 0.0;
  for (int i = 1; i <= 600; ++i) {
    const SpringTrial t = EvaluateSpring(p, s, 0.02 * i);
    s = t.state;
    max_err = std::max(max_err, std::abs(s.z_mm - z_exact(0.02 * i)));
  }
  MESSAGE("600 increments of 0.02 mm: max z error " << max_err << " mm");
  CHECK(max_err < 1e-12 * 4.0 * 600);
  CHECK(s.energy_kN_mm == doctest::Approx(e_exact(12.0)).epsilon(1e-9));
  // A trial does not move the committed state: the same call gives the same bits.
  const SpringTrial again = EvaluateSpring(p, SpringState{}, 12.0);
  CHECK(again.state.z_mm == one.state.z_mm);
  // Unloading with beta = gamma is elastic: dz/du = 1, no dissipation.
  const SpringTrial back = EvaluateSpring(p, s, 10.0);
  CHECK(back.state.z_mm == doctest::Approx(s.z_mm - 2.0).epsilon(1e-12));
  CHECK(back.state.energy_kN_mm == doctest::Approx(s.energy_kN_mm).epsilon(1e-12));
  CHECK(back.tangent_kN_per_mm == doctest::Approx(20.0));
}

TEST_CASE("Baber-Noori degradation lowers the strength and the stiffness with the dissipated energy") {
  SpringParams p = BoucWen(20.0, 0.0, 4.0), deg = p;
  deg.delta_nu = 0.2, deg.delta_eta = 0.2;
  SpringState a, b;
  double fa = 0.0, fb = 0.0;
  for (int cycle = 0; cycle < 5; ++cycle)
    for (int i = 0; i < 400; ++i) {  // +-16 mm cycles
      const double u = 16.0 * std::sin(2 * kPi * (i + 1) / 400.0);
      const SpringTrial ta = EvaluateSpring(p, a, u), tb = EvaluateSpring(deg, b, u);
      a = ta.state, b = tb.state, fa = ta.force_kN, fb = tb.force_kN;
    }
  MESSAGE("after 5 cycles: z " << a.z_mm << " vs degrading " << b.z_mm << " mm; E_h " << a.energy_kN_mm << ", "
                               << b.energy_kN_mm);
  CHECK(std::abs(fb) < std::abs(fa));
  // The degrading spring's peak force in the last cycle is below the non-degrading one's 4 * 20 kN.
  const SpringTrial peak = EvaluateSpring(deg, b, 16.0);
  CHECK(peak.force_kN < 0.9 * 80.0);
}

TEST_CASE("bilinear: a closed cycle dissipates its loop area 4 (1 - b) F_y (u_m - u_y)") {
  const double k = 10.0, b = 0.05, f_y = 20.0, u_y = 2.0, u_m = 7.0;
  const SpringParams p = Bilinear(k, b, f_y);
  SpringState s;
  double area = 0.0, f_prev = 0.0, u_prev = 0.0, e0 = 0.0;
  const int per = 2000;  // samples per cycle
  for (int i = 1; i <= per / 4 + per; ++i) {  // 0 -> u_m (a quarter), then one full cycle
    const double u = u_m * std::sin(2 * kPi * i / per);
    const SpringTrial t = EvaluateSpring(p, s, u);
    if (i > per / 4) area += 0.5 * (t.force_kN + f_prev) * (u - u_prev);
    if (i == per / 4) e0 = t.state.energy_kN_mm;
    s = t.state, f_prev = t.force_kN, u_prev = u;
  }
  const double loop = 4.0 * (1.0 - b) * f_y * (u_m - u_y);
  MESSAGE("loop area " << loop << ", trapezoid " << area << ", E_h over the cycle " << s.energy_kN_mm - e0);
  CHECK(s.energy_kN_mm - e0 == doctest::Approx(loop).epsilon(1e-9));
  CHECK(area == doctest::Approx(loop).epsilon(1e-3));
  // Force at the peak: F_y + b k (u_m - u_y); tangent b k while yielding.
  const SpringTrial t = EvaluateSpring(p, SpringState{}, u_m);
  CHECK(t.force_kN == doctest::Approx(f_y + b * k * (u_m - u_y)));
  CHECK(t.tangent_kN_per_mm == doctest::Approx(b * k));
  CHECK(EvaluateSpring(p, SpringState{}, 1.0).tangent_kN_per_mm == doctest::Approx(k));
}

TEST_CASE("spring and building validation name the field and the range") {
  const auto where = [](const SpringParams& p) {
    try {
      p.Validate();
    } catch (const rths::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  SpringParams p = BoucWen(20, 0.1, 4);
  p.x_y_mm = 0;
  CHECK(where(p) == "x_y_mm: must be in (0, 1e6] (got 0)");
  p = BoucWen(20, 1.0, 4);
  CHECK(where(p) == "alpha: must be in [0, 1) (got 1)");
  p = BoucWen(20, 0.1, 4);
  p.gamma = 0.8;
  CHECK(where(p).rfind("gamma: must satisfy |gamma| <= beta", 0) == 0);
  p = Bilinear(10, 0.05, -1);
  CHECK(where(p) == "f_y_kN: must be in (0, 1e9] (got -1)");
  CHECK(where(Linear(0)) == "k_kN_per_mm: must be in (0, 1e9] (got 0)");
  try {
    NonlinearBuilding::Make({1000, 1000}, {Linear(1), BoucWen(1, 2.0, 1)}, Eigen::MatrixXd::Zero(2, 2), 0, 1);
    FAIL("no throw");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()) == "springs[1]: alpha: must be in [0, 1) (got 2)");
  }
  IntegratorConfig c;
  c.kind = IntegratorKind::kAlphaOs;
  c.alpha = -0.5;
  CHECK_THROWS_WITH(c.Validate(), "alpha: must be in [-1/3, 0] (got -0.5)");
  c.alpha = 0, c.substeps = 2;
  CHECK_THROWS_WITH(c.Validate(), "substeps: must be 1 for alpha_os (got 2)");
}

TEST_CASE("the first-mode equivalent shear building: a shear building's own stories; the benchmark's first mode") {
  using rths::models::FirstModeStoryStiffness;
  // A shear building gives back its own story stiffnesses (its K is what the stories make).
  const std::vector<double> k = {65.0, 295.6, 355.9, 191.9};
  const auto own = FirstModeStoryStiffness(rths::models::MassMatrix({5e5, 4.9e5, 4.9e5, 5.3e5}),
                                           rths::models::StoryStiffnessMatrix(k));
  REQUIRE(own.size() == k.size());
  for (std::size_t i = 0; i < k.size(); ++i) CHECK(own[i] == doctest::Approx(k[i]).epsilon(1e-10));
  // The benchmark's full K (Silva et al. 2020): the shear building keeps the first frequency and mode
  // shape exactly, and the shipped yielding variant's stories are these stiffnesses.
  const auto ref = rths::models::Silva3Structures().reference;
  const auto shear = FirstModeStoryStiffness(ref.M, ref.K);
  const auto file = rths::models::LoadStructureFile(std::string(RTHS_SOURCE_DIR) +
                                                    "/data/buildings/silva3_shear_bouc_wen.txt");
  REQUIRE(file.springs.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CAPTURE(i);
    CHECK(file.springs[i].k_kN_per_mm == doctest::Approx(shear[i]).epsilon(1e-6));
  }
  const auto f_ref = rths::models::ModalAnalysis(ref).frequency_hz;
  const auto f_shear = rths::models::ModalAnalysis(file).frequency_hz;
  MESSAGE(fmt::format("stories {:.6f} {:.6f} {:.6f} kN/mm; f {:.4f} {:.4f} {:.4f} Hz (benchmark {:.4f} {:.4f} {:.4f})",
                      shear[0], shear[1], shear[2], f_shear[0], f_shear[1], f_shear[2], f_ref[0], f_ref[1], f_ref[2]));
  CHECK(f_shear[0] == doctest::Approx(f_ref[0]).epsilon(1e-6));
  CHECK(f_shear[1] < f_ref[1]);  // the frame's higher modes are stiffer than any shear building's with this mode
  // A first mode that reverses has no shear building: refused, naming K.
  Eigen::MatrixXd K(2, 2);
  K << 1.0, 0.9, 0.9, 1.0;  // the lowest mode is (1, -1)
  CHECK_THROWS_WITH_AS(FirstModeStoryStiffness(Eigen::MatrixXd::Identity(2, 2), K),
                       doctest::Contains("no shear building has this first mode"), rths::Error);
}

TEST_CASE("Rayleigh damping gives the two modes their ratios") {
  const Eigen::MatrixXd M = MassMatrix(kMasses9);
  std::vector<SpringParams> springs;
  for (double k : kStories9) springs.push_back(Linear(k));
  const Eigen::MatrixXd K = InitialStiffness(springs);
  const Eigen::MatrixXd C = RayleighDampingMatrix(M, K, 1, 0.02, 3, 0.05);
  StructureMatrices m{M, K, C, {}};
  const Modes modes = ModalAnalysis(m);
  CHECK(modes.damping_ratio[0] == doctest::Approx(0.02).epsilon(1e-9));
  CHECK(modes.damping_ratio[2] == doctest::Approx(0.05).epsilon(1e-9));
  CHECK(modes.damping_ratio[1] < 0.05);
  CHECK((K - ShearBuilding(kMasses9, kStories9, 0.02).K).norm() == 0.0);
}

TEST_CASE("linear springs: central_difference reproduces models::CentralDifference bit for bit") {
  for (const bool nine : {false, true}) {
    CAPTURE(nine);
    std::vector<double> masses = {20000.0};
    std::vector<SpringParams> springs = {Linear(0.02 * std::pow(10 * kPi, 2))};
    Eigen::MatrixXd C = LinearStructure::Sdof(20000, 5, 0.02, 1).C;
    if (nine) {
      masses = kMasses9, springs.clear();
      for (double k : kStories9) springs.push_back(Linear(k));
      C = ModalDampingMatrix(MassMatrix(masses), InitialStiffness(springs), 0.02);
    }
    const NonlinearBuilding b = NonlinearBuilding::Make(masses, springs, C, 0, 2.0);
    const CentralDifference cd = CentralDifference::Make(b.Initial(), 0.0005);
    const StructureIntegrator integ = StructureIntegrator::Make(b, 0.0005, {});
    StructureState ref = MakeState(cd);
    IntegratorState s = MakeIntegratorState(b);
    const std::vector<double> ag = Chirp(0.0005, 8000, 3000.0);
    bool identical = true;
    for (int k = 0; k + 1 < 8000; ++k) {
      const double f = 0.5 * std::sin(0.01 * k);
      Advance(cd, &ref, ag[k], f);
      Advance(integ, &s, ag[k], ag[k + 1], f);
      identical = identical && (ref.x.array() == s.x.array()).all() && (ref.x_prev.array() == s.x_prev.array()).all();
    }
    CHECK(identical);
    CHECK(ref.x.norm() > 1.0);  // it moved
    // A Bouc-Wen building that never yields (x_y far above the drifts): the nonlinear path, the
    // same numbers to rounding.
    std::vector<SpringParams> bw;
    for (const SpringParams& p : springs) bw.push_back(BoucWen(p.k_kN_per_mm, 0.1, 1e6));
    const StructureIntegrator integ_bw =
        StructureIntegrator::Make(NonlinearBuilding::Make(masses, bw, C, 0, 2.0), 0.0005, {});
    const SimulatedRun run = Simulate(integ_bw, ag);
    const SimulatedRun lin = Simulate(integ, ag);
    const double diff = (run.x_mm - lin.x_mm).cwiseAbs().maxCoeff(), peak = lin.x_mm.cwiseAbs().maxCoeff();
    MESSAGE("never-yielding Bouc-Wen vs linear: max difference " << diff << " mm of peak " << peak << " mm");
    CHECK(diff < 1e-4 * peak);  // z = u (1 - O(u / x_y)), drifts up to ~100 mm
  }
}

TEST_CASE("stability: cr and alpha_os stay bounded above the central-difference limit, which throws") {
  // A stiff linear 2-DOF structure: highest frequency about 250 Hz, limit T_min/pi ~ 1.3 ms.
  const std::vector<double> masses = {1000.0, 1000.0};
  const std::vector<SpringParams> springs = {Linear(2000.0), Linear(1000.0)};
  const NonlinearBuilding b = NonlinearBuilding::Make(
      masses, springs, ModalDampingMatrix(MassMatrix(masses), InitialStiffness(springs), 0.0), 1, 1.0);
  const double limit = CentralDifference::Make(b.Initial(), 1e-5).dt_limit_s;
  const double dt = 5.0 * limit;
  CHECK_THROWS_AS(StructureIntegrator::Make(b, dt, {}), rths::Error);
  IntegratorConfig c;
  c.kind = IntegratorKind::kCentralDifference, c.substeps = 8;  // h = dt / 8 < limit: stable again
  CHECK_NOTHROW(StructureIntegrator::Make(b, dt, c));
  for (const IntegratorKind kind : {IntegratorKind::kCr, IntegratorKind::kAlphaOs, IntegratorKind::kNewmarkImplicit}) {
    CAPTURE(rths::NameOf(kIntegratorKindNames, kind));
    IntegratorConfig ck;
    ck.kind = kind;
    const StructureIntegrator integ = StructureIntegrator::Make(b, dt, ck);
    IntegratorState s = MakeIntegratorState(b);
    s.x << 1.0, 2.0;  // free vibration from a displaced shape
    s.x_corr = s.x;
    double early = 0.0, late = 0.0;  // peaks of the first and the last 5000 steps
    for (int k = 0; k < 20000; ++k) {
      Advance(integ, &s, 0.0, 0.0, 0.0);
      (k < 5000 ? early : late) = std::max(k < 5000 ? early : late, s.x.cwiseAbs().maxCoeff());
      if (k >= 5000 && k < 15000) late = 0.0;
    }
    MESSAGE("peak |x| of the first 5000 steps " << early << " mm, of the last 5000 " << late << " mm");
    CHECK(std::isfinite(late));
    CHECK(late <= 1.001 * early);  // no growth (newmark and cr conserve, alpha_os damps)
  }
}

TEST_CASE("every integrator's step allocates nothing") {
  std::vector<SpringParams> springs;
  for (std::size_t i = 0; i < kStories9.size(); ++i)
    springs.push_back(i % 3 == 2 ? Bilinear(kStories9[i], 0.05, kStories9[i] * 2.0)
                                 : BoucWen(kStories9[i], 0.1, 2.0));
  const NonlinearBuilding b = NonlinearBuilding::Make(
      kMasses9, springs, ModalDampingMatrix(MassMatrix(kMasses9), InitialStiffness(springs), 0.02), 0, 1.0);
  const std::vector<double> ag = Chirp(0.0005, 2001, 4000.0);
  for (const IntegratorKind kind : {IntegratorKind::kCentralDifference, IntegratorKind::kCr,
                                    IntegratorKind::kAlphaOs, IntegratorKind::kNewmarkImplicit}) {
    for (const int sub : {1, 3}) {
      if (sub > 1 && (kind == IntegratorKind::kAlphaOs || kind == IntegratorKind::kNewmarkImplicit)) continue;
      CAPTURE(rths::NameOf(kIntegratorKindNames, kind));
      CAPTURE(sub);
      IntegratorConfig c;
      c.kind = kind, c.substeps = sub;
      const StructureIntegrator integ = StructureIntegrator::Make(b, 0.0005, c);
      IntegratorState s = MakeIntegratorState(b);
      const long before = rths_test::AllocationCount();
      for (int k = 0; k < 2000; ++k) Advance(integ, &s, ag[k], ag[k + 1], 0.3);
      CHECK(rths_test::AllocationCount() - before == 0);
      CHECK(s.building.HystereticEnergy() > 0.0);  // the chirp yields it
    }
  }
}
