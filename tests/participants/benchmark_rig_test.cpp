// plant.kind = "benchmark" (lib/models/benchmark_rig.h, docs/benchmark.md): the rig against the
// benchmark plant stepped directly, the load cell's force from the state, DC, the DAQ, the
// benchmark's sensor noise, the [plant.benchmark] keys, and one lockstep run recomputed offline.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "alloc_counter.h"
#include "core/error.h"
#include "io/run_log.h"
#include "models/benchmark_plant.h"
#include "models/benchmark_rig.h"
#include "models/rig.h"
#include "signal/random.h"
#include "run_support.h"
#include "test_support.h"

namespace m = rths::models;
using rths::scenario::ParseScenario;
using rths::scenario::Scenario;
using namespace rths_test;

namespace {

constexpr double kDt = 1.0 / 4096.0;  // the benchmark's loop rate

m::PlantConfig BenchmarkPlantConfig() {
  m::PlantConfig p;
  p.kind = m::PlantKind::kBenchmark;
  return p;
}

/// A command that moves in every step: a 1 mm, 3 Hz sine plus a 0.2 mm, 37 Hz one [mm].
double Command(std::int64_t k) {
  const double t = k * kDt;
  return std::sin(2 * std::numbers::pi * 3.0 * t) + 0.2 * std::sin(2 * std::numbers::pi * 37.0 * t);
}

/// The message of the rths::Error that parsing `text` throws ("" and a failed check if none).
std::string ErrorOf(const std::string& text) {
  try {
    ParseScenario(text, "bench.toml");
  } catch (const rths::Error& e) {
    return e.what();
  }
  FAIL_CHECK("expected an rths::Error for:\n" << text);
  return "";
}

}  // namespace

TEST_CASE("the rig is BenchmarkPlant stepped directly (ZOH, mm edge), whatever plant.specimen says") {
  for (const m::Specimen specimen : {m::Specimen::kMrDamper, m::Specimen::kNone}) {
    m::PlantConfig cfg = BenchmarkPlantConfig();
    cfg.specimen = specimen;
    cfg.current_dynamics = specimen == m::Specimen::kMrDamper;
    const auto rig = m::MakeRig(cfg, kDt);
    const m::BenchmarkPlant plant = m::BenchmarkPlant::Make({}, kDt);
    m::BenchmarkPlantState z;
    CHECK(rig->y_mm() == 0.0);
    CHECK(rig->f_kN() == 0.0);
    CHECK(!rig->TracksDesired());
    int mismatches = 0;
    for (std::int64_t k = 0; k < 2000; ++k) {
      const double y = StepMm(plant, &z, Command(k));
      rig->Step(Command(k), 2.5);  // the current is ignored
      mismatches += rig->y_mm() != y;
      mismatches += rig->MeasuredYMm(0.25) != y + 0.25;  // DAQ off: noise simply adds
      mismatches += rig->current_A() != 0.0;
    }
    CHECK(mismatches == 0);
    CHECK(rig->k() == 2000);
    CHECK(std::abs(rig->y_mm()) > 0.1);  // it moved
  }
}

TEST_CASE("force: f = m_e y'' + c_e y' + k_e y from the state [N -> kN], and the state is [y, y', y'', ...]") {
  m::BenchmarkRigConfig cfg;
  cfg.params = m::PerturbedBenchmarkParams({}, 5);  // c_e and k_e differ from the nominal
  const m::BenchmarkRig rig = m::BenchmarkRig::Make(cfg, kDt);
  const m::BenchmarkPlantParams& p = cfg.params;
  const double c_e = 2.0 * p.zeta_e * std::sqrt(p.m_e_kg * p.k_e_N_per_m);
  m::BenchmarkRigState s;
  std::vector<double> y_m;  // true displacement [m] per sample
  std::vector<double> f_kN;
  for (std::int64_t k = 0; k < 4096; ++k) {
    y_m.push_back(1e-3 * TrueDisplacementMm(rig, s));
    f_kN.push_back(MeasuredForceKn(rig, s));
    const auto& z = s.plant.z;
    CHECK(f_kN.back() == doctest::Approx(1e-3 * (p.m_e_kg * z(2) + c_e * z(1) + p.k_e_N_per_m * z(0))).epsilon(1e-12));
    Step(rig, &s, std::sin(2 * std::numbers::pi * 20.0 * k * kDt));  // 1 mm, 20 Hz: m_e y'' is 40 % of k_e y
  }
  // Independently of the realisation: y' and y'' by central differences of the sampled y
  // (20 Hz sampled at 4096 Hz: truncation error (w dt)^2 / 12 = 8e-5 of m_e y'', 0.04 N).
  double worst = 0.0, peak = 0.0;
  for (std::size_t k = 2048; k + 1 < y_m.size(); ++k) {
    const double v = (y_m[k + 1] - y_m[k - 1]) / (2 * kDt);
    const double a = (y_m[k + 1] - 2 * y_m[k] + y_m[k - 1]) / (kDt * kDt);
    const double f = 1e-3 * (p.m_e_kg * a + c_e * v + p.k_e_N_per_m * y_m[k]);
    worst = std::max(worst, std::abs(f - f_kN[k]));
    peak = std::max(peak, std::abs(f_kN[k]));
  }
  CHECK(peak > 0.3);               // (k_e - m_e w^2) y: about 0.7 kN
  CHECK(worst < 3e-4 * peak);      // the same force to 0.03 % (leaving out m_e y'' would miss by 60 %)
}

TEST_CASE("DC: a constant 1 mm command settles to y = DcGain mm and f = k_e y") {
  const auto rig = m::MakeRig(BenchmarkPlantConfig(), kDt);
  const m::BenchmarkPlant plant = m::BenchmarkPlant::Make({}, kDt);
  for (int k = 0; k < 6 * 4096; ++k) rig->Step(1.0, 0.0);
  CHECK(rig->y_mm() == doctest::Approx(plant.DcGain()).epsilon(1e-9));
  CHECK(rig->y_mm() == doctest::Approx(1.0075).epsilon(1e-4));
  const m::BenchmarkPlantParams p;
  CHECK(rig->f_kN() == doctest::Approx(1e-3 * p.k_e_N_per_m * 1e-3 * rig->y_mm()).epsilon(1e-9));
  CHECK(rig->f_kN() == doctest::Approx(1.199).epsilon(1e-3));  // 1.19e6 N/m x 1.0075 mm
}

TEST_CASE("DAQ: saturation, quantisation step, mid-tread zero, off = identity") {
  m::BenchmarkDaqConfig daq;  // 100 V/m, +/-3.8 V, 18 bits
  const double q = DaqStepMm(daq);
  CHECK(q == doctest::Approx(2 * 3.8 / std::pow(2.0, 18) / 0.1).epsilon(1e-15));  // 2.9e-4 mm
  // Off: identity, bit for bit.
  for (double x : {0.0, 1e-9, -0.123456789, 37.9, 1e6}) CHECK(DaqConvertMm(daq, x) == x);
  daq.enabled = true;
  // Saturation at +/- saturation_V / volts_per_m (38 mm); the top code is one step below.
  CHECK(DaqConvertMm(daq, -1000.0) == doctest::Approx(-38.0).epsilon(1e-15));
  CHECK(DaqConvertMm(daq, -38.0) == doctest::Approx(-38.0).epsilon(1e-15));
  CHECK(DaqConvertMm(daq, 1000.0) == doctest::Approx(38.0 - q).epsilon(1e-15));
  CHECK(DaqConvertMm(daq, 50.0) == DaqConvertMm(daq, 1000.0));
  // Mid-tread: 0 is a level, anything within half a step reads 0.
  CHECK(DaqConvertMm(daq, 0.0) == 0.0);
  CHECK(DaqConvertMm(daq, 0.49 * q) == 0.0);
  CHECK(DaqConvertMm(daq, -0.49 * q) == 0.0);
  CHECK(DaqConvertMm(daq, 0.51 * q) == doctest::Approx(q).epsilon(1e-12));
  // Inside the range: a multiple of the step within half a step of the input, and idempotent.
  int bad = 0;
  for (int i = 0; i < 2000; ++i) {
    const double x = 37.0 * std::sin(0.37 * i + 0.1);
    const double d = DaqConvertMm(daq, x);
    const double n = d / q;
    bad += std::abs(d - x) > 0.5 * q * (1 + 1e-9);
    bad += std::abs(n - std::round(n)) > 1e-6;
    bad += DaqConvertMm(daq, d) != d;
  }
  CHECK(bad == 0);
  // Fewer bits, a coarser step: 4 bits over +/-3.8 V at 100 V/m is 4.75 mm.
  daq.bits = 4;
  CHECK(DaqStepMm(daq) == doctest::Approx(4.75).epsilon(1e-12));
  CHECK(DaqConvertMm(daq, 2.0) == 0.0);
  CHECK(DaqConvertMm(daq, 2.5) == doctest::Approx(4.75).epsilon(1e-12));
  CHECK(DaqConvertMm(daq, 100.0) == doctest::Approx(7 * 4.75).epsilon(1e-12));  // top code 2^3 - 1
  CHECK(DaqConvertMm(daq, -100.0) == doctest::Approx(-8 * 4.75).epsilon(1e-12));

  m::BenchmarkDaqConfig bad_daq;
  bad_daq.bits = 1;
  CHECK_THROWS_AS(m::ValidateBenchmarkDaq(bad_daq), rths::Error);
  bad_daq = {};
  bad_daq.volts_per_m = 0.0;
  CHECK_THROWS_AS(m::BenchmarkRig::Make({{}, bad_daq}, kDt), rths::Error);
}

TEST_CASE("DAQ in the rig: the command through the D/A, y (with its noise) through the A/D") {
  m::PlantConfig cfg = BenchmarkPlantConfig();
  cfg.benchmark.daq.enabled = true;
  cfg.benchmark.daq.bits = 10;  // a visible step: 7.6 V / 1024 / 0.1 V/mm = 0.074 mm
  const auto rig = m::MakeRig(cfg, kDt);
  const m::BenchmarkPlant plant = m::BenchmarkPlant::Make({}, kDt);
  const auto& daq = cfg.benchmark.daq;
  m::BenchmarkPlantState z;
  int mismatches = 0, off_grid = 0;
  const double q = DaqStepMm(daq);
  for (std::int64_t k = 0; k < 3000; ++k) {
    const double y_true = StepMm(plant, &z, DaqConvertMm(daq, Command(k)));
    rig->Step(Command(k), 0.0);
    mismatches += rig->y_mm() != DaqConvertMm(daq, y_true);
    const double noise = 0.3 * q * std::sin(0.7 * k);
    mismatches += rig->MeasuredYMm(noise) != DaqConvertMm(daq, y_true + noise);
    const double n = rig->MeasuredYMm(noise) / q;
    off_grid += std::abs(n - std::round(n)) > 1e-6;
  }
  CHECK(mismatches == 0);
  CHECK(off_grid == 0);
  // The D/A changed the motion: the same commands without it give another y.
  const auto plain = m::MakeRig(BenchmarkPlantConfig(), kDt);
  for (std::int64_t k = 0; k < 3000; ++k) plain->Step(Command(k), 0.0);
  CHECK(plain->y_mm() != rig->y_mm());
}

TEST_CASE("Rig::Step of the benchmark allocates nothing") {
  const auto rig = m::MakeRig(BenchmarkPlantConfig(), kDt);
  rig->Step(0.1, 0.0);
  const long before = AllocationCount();
  double sink = 0.0;
  for (int k = 0; k < 1000; ++k) {
    rig->Step(Command(k), 0.0);
    sink += rig->y_mm() + rig->f_kN() + rig->MeasuredYMm(0.01);
  }
  CHECK(AllocationCount() == before);
  CHECK(std::isfinite(sink));
}

TEST_CASE("the benchmark's sensor noise: variance = power / dt") {
  const m::BenchmarkNoiseRms n = m::BenchmarkSensorNoise(kDt);
  CHECK(n.y_mm == doctest::Approx(0.016).epsilon(1e-12));  // 1e3 sqrt(6.25e-14 x 4096) exactly 0.016
  CHECK(n.f_kN == doctest::Approx(1e-3 * std::sqrt(1.16e-3 * 4096)).epsilon(1e-12));
  CHECK(n.f_kN == doctest::Approx(0.00218).epsilon(1e-3));
  const m::BenchmarkNoiseRms half = m::BenchmarkSensorNoise(kDt / 2);  // twice the rate, sqrt(2) x the RMS
  CHECK(half.y_mm == doctest::Approx(std::sqrt(2.0) * n.y_mm).epsilon(1e-12));
  CHECK(half.f_kN == doctest::Approx(std::sqrt(2.0) * n.f_kN).epsilon(1e-12));
  CHECK_THROWS_AS(m::BenchmarkSensorNoise(0.0), rths::Error);
  CHECK_THROWS_AS(m::BenchmarkSensorNoise(NAN), rths::Error);
  // The keys' ranges allow them, down to the smallest run.dt_s (1e-5 s: 0.079 mm, 0.0108 kN).
  const m::BenchmarkNoiseRms fastest = m::BenchmarkSensorNoise(1e-5);
  const Scenario s = ParseScenario(
      "[run]\ndt_s = 1e-5\nduration_s = 0.01\n[plant]\nkind = \"benchmark\"\nnoise_y_mm_rms = " +
          std::to_string(fastest.y_mm) + "\nnoise_f_kN_rms = " + std::to_string(fastest.f_kN) + "\n",
      "noise.toml");
  CHECK(s.plant.noise_y_mm_rms > 0.07);
}

TEST_CASE("scenario: the example file, defaults, every [plant.benchmark] key and the ToToml round trip") {
  const Scenario ex =
      rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/benchmark_plant_blwn.toml");
  CHECK(ex.plant.kind == m::PlantKind::kBenchmark);
  CHECK(ex.plant.benchmark == m::BenchmarkRigConfig{});  // nominal, DAQ off
  CHECK(ex.run.dt_s == kDt);
  CHECK(ex.steps() == 20 * 4096);
  CHECK(ex.controller.kind == rths::control::ControllerKind::kNone);
  CHECK(ex.structure.mode == m::StructureMode::kPredefined);
  CHECK(ex.structure.desired.kind == rths::signal::SignalKind::kBlwn);
  CHECK(ex.structure.desired.band_hz == 20.0);
  CHECK(ex.structure.desired.rms == 1.0);
  const m::BenchmarkNoiseRms noise = m::BenchmarkSensorNoise(kDt);
  CHECK(ex.plant.noise_y_mm_rms == doctest::Approx(noise.y_mm).epsilon(1e-4));
  CHECK(ex.plant.noise_f_kN_rms == doctest::Approx(noise.f_kN).epsilon(1e-4));

  // Defaults without the table: the nominal plant.
  const Scenario d = ParseScenario("[plant]\nkind = \"benchmark\"\n", "d.toml");
  CHECK(d.plant.benchmark.params == m::BenchmarkPlantParams{});
  CHECK(!d.plant.benchmark.daq.enabled);
  CHECK(d.plant.benchmark.daq.volts_per_m == 100.0);
  CHECK(d.plant.benchmark.daq.saturation_V == 3.8);
  CHECK(d.plant.benchmark.daq.bits == 18);

  // Every key read, and written back by ToToml.
  const Scenario s = ParseScenario(R"(
[plant]
kind = "benchmark"
[plant.benchmark]
gain = 1.1
a1b0 = 2.2e13
a2 = 4.3e6
a3 = -0.5
b1 = 430.0
b2 = 1.01e5
m_e_kg = 30.0
k_e_N_per_m = 1.2e6
zeta_e = 0.02
[plant.benchmark.daq]
enabled = true
volts_per_m = 250.0
saturation_V = 10.0
bits = 16
)",
                                   "all.toml");
  const m::BenchmarkRigConfig& b = s.plant.benchmark;
  CHECK(b.params.gain == 1.1);
  CHECK(b.params.a1b0 == 2.2e13);
  CHECK(b.params.a2 == 4.3e6);
  CHECK(b.params.a3 == -0.5);
  CHECK(b.params.b1 == 430.0);
  CHECK(b.params.b2 == 1.01e5);
  CHECK(b.params.m_e_kg == 30.0);
  CHECK(b.params.k_e_N_per_m == 1.2e6);
  CHECK(b.params.zeta_e == 0.02);
  CHECK(b.daq.enabled);
  CHECK(b.daq.volts_per_m == 250.0);
  CHECK(b.daq.saturation_V == 10.0);
  CHECK(b.daq.bits == 16);
  const std::string text = rths::scenario::ToToml(s);
  CHECK(text.find("[plant.benchmark]") != std::string::npos);
  CHECK(text.find("[plant.benchmark.daq]") != std::string::npos);
  Scenario back = ParseScenario(text, "all.toml");
  CHECK(back.plant.benchmark == s.plant.benchmark);
  CHECK(back.plant == s.plant);
  CHECK(rths::scenario::ToToml(back) == text);
  // --set reaches the keys.
  const Scenario set = rths::scenario::WithOverrides(s, {"plant.benchmark.b1=440", "plant.benchmark.daq.bits=12"});
  CHECK(set.plant.benchmark.params.b1 == 440.0);
  CHECK(set.plant.benchmark.daq.bits == 12);
}

TEST_CASE("scenario errors name plant.benchmark.<key> and its range") {
  const std::string head = "[plant]\nkind = \"benchmark\"\n[plant.benchmark]\n";
  struct Case {
    std::string line, key, range;
  };
  for (const Case& c : std::vector<Case>{{"gain = 0", "plant.benchmark.gain", "(0, inf)"},
                                         {"a1b0 = -1", "plant.benchmark.a1b0", "(0, inf)"},
                                         {"a2 = -1", "plant.benchmark.a2", "[0, inf)"},
                                         {"a3 = inf", "plant.benchmark.a3", "any finite value"},
                                         {"b1 = 0", "plant.benchmark.b1", "(0, inf)"},
                                         {"b2 = -5", "plant.benchmark.b2", "(0, inf)"},
                                         {"m_e_kg = 0", "plant.benchmark.m_e_kg", "(0, inf)"},
                                         {"k_e_N_per_m = nan", "plant.benchmark.k_e_N_per_m", "(0, inf)"},
                                         {"zeta_e = -0.01", "plant.benchmark.zeta_e", "[0, inf)"}}) {
    CAPTURE(c.line);
    const std::string e = ErrorOf(head + c.line + "\n");
    CHECK(e.find("bench.toml: " + c.key + ": ") == 0);
    CHECK(e.find(c.range) != std::string::npos);
  }
  const std::string daq = "[plant]\nkind = \"benchmark\"\n[plant.benchmark.daq]\n";
  for (const Case& c : std::vector<Case>{{"volts_per_m = 0", "plant.benchmark.daq.volts_per_m", "(0, inf)"},
                                         {"saturation_V = -3.8", "plant.benchmark.daq.saturation_V", "(0, inf)"},
                                         {"bits = 1", "plant.benchmark.daq.bits", "[2, 32]"},
                                         {"bits = 33", "plant.benchmark.daq.bits", "[2, 32]"}}) {
    CAPTURE(c.line);
    const std::string e = ErrorOf(daq + c.line + "\n");
    CHECK(e.find("bench.toml: " + c.key + ": ") == 0);
    CHECK(e.find(c.range) != std::string::npos);
  }
  // Wrong types and unknown keys.
  CHECK(ErrorOf(daq + "bits = 18.5\n").find("plant.benchmark.daq.bits: expected an integer") != std::string::npos);
  CHECK(ErrorOf(daq + "enabled = 1\n").find("plant.benchmark.daq.enabled: expected a boolean") != std::string::npos);
  const std::string unknown = ErrorOf(head + "k_e = 1.2e6\n");
  CHECK(unknown.find("plant.benchmark.k_e: unknown key") != std::string::npos);
  CHECK(unknown.find("did you mean \"plant.benchmark.k_e_N_per_m\"") != std::string::npos);
  // Gp's stability across keys, named at the table.
  const std::string unstable = ErrorOf(head + "a1b0 = 1e20\n");
  CHECK(unstable.find("bench.toml: plant.benchmark: the plant Gp is unstable") == 0);
  // Rig mode keeps needing the linear plant.
  const std::string rig_mode = ErrorOf("[plant]\nkind = \"benchmark\"\n[plant.effects.pure_delay]\ntau_ms = 1.0\n");
  CHECK(rig_mode.find("plant.effects: rig mode needs plant.kind = \"linear\" (got \"benchmark\")") != std::string::npos);
  // The kind is listed among the allowed ones.
  CHECK(ErrorOf("[plant]\nkind = \"bench\"\n").find("\"benchmark\"") != std::string::npos);
}

TEST_CASE("lockstep run (memq): the logged y and f are the plant stepped offline on the logged u, noise and DAQ included") {
  const auto dir = TempDir("benchmark_rig_lockstep");
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
dt_s = 0.000244140625
duration_s = 0.25
[structure]
mode = "predefined"
[structure.desired]
kind = "blwn"
band_hz = 20.0
rms_mm = 1.0
seed = 4
[controller]
kind = "none"
[plant]
kind = "benchmark"
specimen = "mr_damper"   # ignored by this kind
noise_y_mm_rms = 0.016
noise_f_kN_rms = 0.0021798
noise_seed = 11
[plant.benchmark]
k_e_N_per_m = 1.25e6
[plant.benchmark.daq]
enabled = true
[semiactive]
mode = "constant"
current_A = 1.0
)").string());
  REQUIRE(RunMemq({s}, dir).code == 0);
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  const std::int64_t n = s.steps();
  REQUIRE(n == 1024);
  REQUIRE(log.CompleteSteps() == n);

  const m::BenchmarkRig rig = m::BenchmarkRig::Make(s.plant.benchmark, s.run.dt_s);
  m::BenchmarkRigState state;
  rths::signal::GaussianState noise = rths::signal::MakeGaussian(s.plant.noise_seed);
  int mismatches = 0;
  double moved = 0.0;
  for (std::int64_t k = 0; k < n; ++k) {
    // The plant draws y's noise, then f's, once per sample in step order.
    const double ny = s.plant.noise_y_mm_rms * rths::signal::NextGaussian(&noise);
    const double nf = s.plant.noise_f_kN_rms * rths::signal::NextGaussian(&noise);
    const auto& meas = log.measured[k];
    mismatches += meas.y_mm != MeasuredDisplacementMm(rig, state, ny);
    mismatches += meas.f_kN != MeasuredForceKn(rig, state) + nf;
    mismatches += meas.current_A != 0.0;
    mismatches += log.command[k].u_mm != log.desired[k].r_mm;  // controller "none"
    moved = std::max(moved, std::abs(TrueDisplacementMm(rig, state)));
    Step(rig, &state, log.command[k].u_mm);  // u_k held over [t_k, t_{k+1})
  }
  CHECK(mismatches == 0);
  CHECK(moved > 0.2);
  // A one-step shift would not match: y_k does not contain u_k. (Counted where the motion over
  // the step exceeds two converter steps, so that the shift is visible through the DAQ.)
  m::BenchmarkRigState now, ahead;
  rths::signal::GaussianState noise2 = rths::signal::MakeGaussian(s.plant.noise_seed);
  int eligible = 0, shifted_equal = 0;
  const double q = DaqStepMm(s.plant.benchmark.daq);
  for (std::int64_t k = 0; k + 1 < n; ++k) {
    const double ny = s.plant.noise_y_mm_rms * rths::signal::NextGaussian(&noise2);
    rths::signal::NextGaussian(&noise2);
    Step(rig, &ahead, log.command[k].u_mm);
    if (std::abs(TrueDisplacementMm(rig, ahead) - TrueDisplacementMm(rig, now)) > 2 * q) {
      ++eligible;
      shifted_equal += log.measured[k].y_mm == MeasuredDisplacementMm(rig, ahead, ny);
    }
    Step(rig, &now, log.command[k].u_mm);
  }
  CHECK(eligible > n / 2);
  CHECK(shifted_equal == 0);
}
