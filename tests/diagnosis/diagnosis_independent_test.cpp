// The diagnosis on records of the INDEPENDENT generator (lib/validation/independent_rig.h: a
// continuous RK4 simulation written apart from the rig mode, with its own effect forms,
// excitation families and anti-aliased sensor noise; docs/diagnosis.md "Validation harness").
// The generator's own integration is checked against a twice-finer one; nominal records (no
// effect) must give "none" over several bands and current patterns; then a bounded harness run
// (seeds 1-2, 6 s records, every independent case kind) against the harness targets.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "validation/harness.h"
#include "harness_support.h"
#include "validation/independent_rig.h"

using namespace rths::diagnosis;
using namespace rths::validation;

namespace {

double NrmsePctOf(const std::vector<double>& ref, const std::vector<double>& x) {
  double se = 0, sr = 0;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    se += (ref[k] - x[k]) * (ref[k] - x[k]);
    sr += ref[k] * ref[k];
  }
  return 100.0 * std::sqrt(se / sr);
}

// The El Centro record of the earthquake commands, read here (the generator takes data, not paths).
const std::vector<double>& ElCentroG() {
  static const std::vector<double> g =
      ReadGroundMotion(std::string(RTHS_SOURCE_DIR) + "/data/ground_motion/elcentro_1940_ns_g.txt");
  return g;
}

IndependentExcitation Ex(CommandFamily f, double lo, double hi, CurrentPattern p, std::uint64_t seed) {
  IndependentExcitation e;
  e.duration_s = 6.0;
  e.command = f;
  e.lo_hz = lo;
  e.hi_hz = hi;
  e.rms_mm = f == CommandFamily::kEarthquake ? 8.0 : 4.0;
  e.current = p;
  e.current_max_A = p == CurrentPattern::kConstant ? 1.2 : 2.5;
  e.current_period_s = 0.7;
  e.seed = seed;
  if (f == CommandFamily::kEarthquake) e.ground_g = ElCentroG();
  return e;
}

}  // namespace

TEST_CASE("independent generator: RK4 converges (M substeps against 2M)") {
  const auto ex = Ex(CommandFamily::kBandNoise, 0.0, 40.0, CurrentPattern::kPulsed, 3);
  std::vector<double> u, i;
  MakeIndependentInputs(ex, &u, &i);
  struct Variant {
    const char* name;
    IndependentTruth t;
  };
  std::vector<Variant> vs(6);
  vs[0].name = "nominal";
  vs[1].name = "delay 2.37 ms + oil 25 Hz";
  vs[1].t.delay_ms = 2.37, vs[1].t.oil_f_hz = 25.0, vs[1].t.oil_zeta = 0.1;
  vs[2].name = "backlash 0.3 mm";
  vs[2].t.backlash_gap_mm = 0.3;
  vs[3].name = "load coupling 1e-3 mm/kN";
  vs[3].t.compliance_mm_per_kN = 1e-3;
  vs[4].name = "friction 0.2 mm + current lag 60 ms";
  vs[4].t.friction_loss_mm = 0.2, vs[4].t.current_lag_ms = 60.0;
  vs[5].name = "vmax 200 mm/s + damper scale 1.2";
  vs[5].t.vmax_mm_per_s = 200.0, vs[5].t.damper_scale = 1.2;
  std::string report;
  for (auto& v : vs) {
    v.t.substeps = 8;
    const auto a = SimulateIndependent(u, i, ex.dt_s, v.t);
    v.t.substeps = 16;
    const auto b = SimulateIndependent(u, i, ex.dt_s, v.t);
    const double ey = NrmsePctOf(b.y_mm, a.y_mm), ef = NrmsePctOf(b.f_kN, a.f_kN);
    report += fmt::format("{:<36} y {:.2e} %  f {:.2e} %  (up to {} substeps)\n", v.name, ey, ef, a.substeps_max);
    CHECK(ey < 1e-3);
    CHECK(ef < 0.02);
  }
  MESSAGE(report);
}

TEST_CASE("independent generator: sample pairing, a delay that is not a whole number of samples") {
  // A step of u at sample 100: y_k depends on u up to u_{k-1}, so y_100 = 0 and y_101 > 0; a delay of
  // 2.5 samples moves the first motion to sample 103 (the command switches at t_102.5).
  IndependentExcitation ex;
  std::vector<double> u(2000, 0.0), i(2000, 1.0);
  for (std::size_t k = 100; k < u.size(); ++k) u[k] = 1.0;
  IndependentTruth t;
  const auto a = SimulateIndependent(u, i, ex.dt_s, t);
  CHECK(a.y_mm[100] == 0.0);
  CHECK(a.y_mm[101] > 0.0);
  t.delay_ms = 2.5 * ex.dt_s * 1e3;
  const auto b = SimulateIndependent(u, i, ex.dt_s, t);
  CHECK(b.y_mm[102] == 0.0);
  CHECK(b.y_mm[103] > 0.0);
  // DC gain of Eq. 30, K / (p c) = 0.99407.
  CHECK(a.y_mm.back() == doctest::Approx(0.99407).epsilon(1e-4));
}

TEST_CASE("independent generator: nominal records give none (several bands, current patterns, noise colours)") {
  struct Pair {
    IndependentExcitation train, test;
    NoiseColour colour;
    double ny, nf;
  };
  std::vector<Pair> pairs = {
      // The issue's withheld check: training band noise to 40 Hz with a pulsed current, test to 12 Hz, white noise.
      {Ex(CommandFamily::kBandNoise, 0.0, 40.0, CurrentPattern::kPulsed, 1),
       Ex(CommandFamily::kBandNoise, 0.0, 12.0, CurrentPattern::kPulsed, 2), NoiseColour::kWhite, 0.002, 0.05},
      {Ex(CommandFamily::kChirp, 0.5, 40.0, CurrentPattern::kStaircase, 3),
       Ex(CommandFamily::kMultisine, 0.3, 10.0, CurrentPattern::kConstant, 4), NoiseColour::kWhite, 0.002, 0.05},
      {Ex(CommandFamily::kMultisine, 0.5, 30.0, CurrentPattern::kTelegraph, 5),
       Ex(CommandFamily::kEarthquake, 2.5, 0.0, CurrentPattern::kConstant, 6), NoiseColour::kAntiAliased, 0.01, 0.2},
      {Ex(CommandFamily::kBandNoise, 2.0, 60.0, CurrentPattern::kTelegraph, 7),
       Ex(CommandFamily::kChirp, 0.3, 20.0, CurrentPattern::kPulsed, 8), NoiseColour::kAntiAliased, 0.002, 0.05},
  };
  int j = 0;
  for (const auto& p : pairs) {
    IndependentTruth t;
    t.colour = p.colour;
    t.noise_y_mm = p.ny, t.noise_f_kN = p.nf;
    t.noise_seed = 100 + j;
    const auto tr = MakeIndependentRecord(p.train, t, fmt::format("none{}-train", j));
    t.noise_seed = 200 + j;
    const auto te = MakeIndependentRecord(p.test, t, fmt::format("none{}-test", j));
    const Result r = Diagnose({tr}, {te}, PaperModel(), Options{});
    INFO(fmt::format("pair {}: {} -> {}\n{}", j, tr.Meta("command"), te.Meta("command"), Summary(r)));
    CHECK(r.verdict == std::vector<std::string>{"none"});
    for (const auto& c : r.channels) CHECK(c.floor_ratio <= Options{}.none_ratio);
    ++j;
  }
}

TEST_CASE("a nominal record cut from a longer acquisition (starting in motion, current on) sits at the noise floor") {
  // A dwell-and-sweep test whose first 1.3 s were cut off: the rig's damper is mid-hysteresis and
  // its current driver mid-rise at the record's first sample; the model starts at rest.
  const double dt = 0.0005, pi = std::numbers::pi;
  std::vector<double> u, i;
  for (double f : {0.5, 2.0, 5.0})
    for (int k = 0; k < static_cast<int>(4.0 / dt); ++k) u.push_back(4.0 * std::sin(2.0 * pi * f * k * dt));
  const double T = 12.0, f0 = 0.5, f1 = 20.0;
  for (int k = 0; k < static_cast<int>(T / dt); ++k) {
    const double t = k * dt;
    u.push_back(2.0 * std::sin(2.0 * pi * f0 * T / std::log(f1 / f0) * (std::exp(t / T * std::log(f1 / f0)) - 1.0)));
  }
  for (std::size_t k = 0; k < u.size(); ++k) i.push_back((k / 2000) % 2 ? 2.5 : 0.0);
  IndependentTruth truth;
  const auto sim = SimulateIndependent(u, i, dt, truth);
  const auto ny = IndependentNoise(u.size(), dt, truth.noise_y_mm, truth.colour, truth.drift_fraction, 5);
  const auto nf = IndependentNoise(u.size(), dt, truth.noise_f_kN, truth.colour, truth.drift_fraction, 6);
  rths::io::RigRecord cut;
  cut.dt_s = dt;
  cut.source = "dwell_sweep_cut";
  const std::size_t skip = static_cast<std::size_t>(1.3 / dt);  // the current came on at 1.0 s
  for (std::size_t k = skip; k < u.size(); ++k) {
    cut.t_s.push_back(static_cast<double>(k - skip) * dt);
    cut.u_mm.push_back(u[k]);
    cut.y_mm.push_back(sim.y_mm[k] + ny[k]);
    cut.f_kN.push_back(sim.f_kN[k] + nf[k]);
    cut.i_A.push_back(i[k]);
  }
  IndependentExcitation ex;
  ex.duration_s = 12.0;
  ex.seed = 77;
  const auto test = MakeIndependentRecord(ex, truth, "blwn_test");
  const Result r = Diagnose({cut}, {test}, PaperModel(), Options{});
  INFO(Summary(r));
  CHECK(r.verdict == std::vector<std::string>{"none"});
  CHECK(r.Channel("f")->floor_ratio < 1.3);  // 89 when the sums started at 0.1 s
  bool noted = false;
  for (const auto& w : r.warnings) noted = noted || w.find("dwell_sweep_cut: starts in motion") != std::string::npos;
  CHECK(noted);
}

TEST_CASE("harness (independent generator): confusion table and held-out shrink meet the harness targets") {
  HarnessOptions o;
  o.seeds = 2;
  o.duration_s = 6.0;
  o.generator = Generator::kIndependent;
  o.pairs = true;
  o.ground_g = ElCentroG();
  // Every kind on two seeds but the pairs of issue 42 (short presliding beside six effects, the
  // in-loop flow limit and the DAQ's effects beside force effects: 9), which run on one.
  const auto kinds = CaseKinds(o.generator, true);
  const auto new_kinds = rths_test::Issue42Kinds(kinds);
  HarnessOptions o_new = o;
  o_new.seeds = 1;
  for (const auto& k : kinds) {
    const bool is_new_pair = k.find('+') != std::string::npos &&
                             std::find(new_kinds.begin(), new_kinds.end(), k) != new_kinds.end();
    (is_new_pair ? o_new.only : o.only).push_back(k);
  }
  REQUIRE(o_new.only.size() == 9);
  const auto sc = rths_test::RunHarnessReported({o, o_new});
  REQUIRE(sc.single_n == 17 * o.seeds);  // 14 effects, servovalve_saturation's @loop and @unreached, short presliding
  REQUIRE(sc.pair_n == 10 * o.seeds + 9);
  REQUIRE(sc.none_n == 4 * o.seeds);     // none, none_white, none_drift, none_current_on
  REQUIRE(sc.unknown_n == 4 * o.seeds);  // ripple, cubic, asymmetric, heating
  rths_test::CheckHarnessTargets(sc);
  CHECK(sc.none_right == sc.none_n);
  CHECK(sc.unknown_right == sc.unknown_n);
}
