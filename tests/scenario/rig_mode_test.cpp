// Tests for the rig mode (docs/rig_mode.md): the scenario keys of [plant.effects.<name>],
// [plant.unmodelled] and [plant.damper]; each effect's signature through models::MakeRig; seeded
// determinism; a lockstep run with effects on and its rig record (the `rths record` path).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "alloc_counter.h"
#include "core/error.h"
#include "io/rig_record.h"
#include "io/run_log.h"
#include "models/effect_rig.h"
#include "models/rig.h"
#include "scenario/scenario.h"
#include "run_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths::scenario::ParseScenario;
using rths::models::PlantConfig;
using rths::scenario::Scenario;

namespace {

constexpr double kDt = 0.0005;
constexpr double kPi = 3.14159265358979323846;

/// The message of the rths::Error that parsing `text` throws ("" and a failed check if none).
std::string ErrorOf(std::string_view text, const std::string& path = "bad.toml") {
  try {
    ParseScenario(text, path);
  } catch (const rths::Error& e) {
    return e.what();
  }
  FAIL_CHECK("expected an rths::Error for:\n" << text);
  return "";
}

void CheckContains(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (std::string_view part : parts) {
    CHECK_MESSAGE(message.find(part) != std::string::npos, "\"" << part << "\" not in: " << message);
  }
}

/// A plant of kind "linear" (Eq. 30), the Table 3 damper, current dynamics on.
PlantConfig LinearPlant() {
  PlantConfig p;
  p.kind = rths::models::PlantKind::kLinear;
  return p;
}

/// Response of a rig to command / current sequences: y_k and f_k for k = 0 .. n.
struct Response {
  std::vector<double> y, f, i;
};
template <class U, class I>
Response Drive(const PlantConfig& plant, int n, U u_of_k, I i_of_k) {
  auto rig = rths::models::MakeRig(plant, kDt);
  Response r;
  r.y.push_back(rig->y_mm());
  r.f.push_back(rig->f_kN());
  r.i.push_back(rig->current_A());
  for (int k = 0; k < n; ++k) {
    rig->Step(u_of_k(k), i_of_k(k));
    r.y.push_back(rig->y_mm());
    r.f.push_back(rig->f_kN());
    r.i.push_back(rig->current_A());
  }
  return r;
}

/// First sample index at which |v| reaches `level` (or -1).
int FirstCrossing(const std::vector<double>& v, double level) {
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (v[k] >= level) return static_cast<int>(k);
  }
  return -1;
}

/// Time [s] at which v first reaches `level`, linearly interpolated between samples.
double CrossingTimeS(const std::vector<double>& v, double level) {
  const int k = FirstCrossing(v, level);
  REQUIRE(k > 0);
  const double frac = (level - v[k - 1]) / (v[k] - v[k - 1]);
  return (k - 1 + frac) * kDt;
}

double Rms(const std::vector<double>& v, std::size_t from = 0) {
  double s = 0.0;
  for (std::size_t k = from; k < v.size(); ++k) s += v[k] * v[k];
  return std::sqrt(s / static_cast<double>(v.size() - from));
}

const char* kBase = R"(
[run]
dt_s = 0.0005
duration_s = 1.0
)";

}  // namespace

// ---------------------------------------------------------------------------------------------
// Scenario keys

TEST_CASE("scenario: every effect of the library is read from [plant.effects.<name>] and written back") {
  const std::string text = std::string(kBase) + R"(
[plant.effects.pure_delay]
tau_ms = 2.5
[plant.effects.gain_error]
gain = 0.95
[plant.effects.load_coupling]
compliance_mm_per_kN = 0.004
same_sample = true
[plant.effects.oil_column_resonance]
f_hz = 55.0
zeta = 0.08
[plant.effects.coulomb_friction]
loss_mm = 0.05
v_smooth_mm_s = 2.0
[plant.effects.backlash]
gap_mm = 0.1
[plant.effects.servovalve_saturation]
vmax_mm_per_s = 300.0
[plant.effects.sensor_noise]
rms_y_mm = 0.002
rms_f_kN = 0.05
[plant.effects.current_lag]
tau_ms = 20.0
[plant.effects.damper_scale]
scale = 1.2

[plant.unmodelled]
ripple_mm = 0.05
ripple_hz = 37.0
stiffness_kN_per_mm = 0.5

[plant.damper]
alpha_a = 0.12
k1 = 0.01
)";
  const Scenario s = ParseScenario(text, "effects.toml");
  const auto& e = s.plant.effects;
  REQUIRE(e.pure_delay);
  CHECK(e.pure_delay->tau_ms == 2.5);
  REQUIRE(e.gain_error);
  CHECK(e.gain_error->gain == 0.95);
  REQUIRE(e.load_coupling);
  CHECK(e.load_coupling->compliance_mm_per_kN == 0.004);
  REQUIRE(e.oil_column_resonance);
  CHECK(e.oil_column_resonance->f_hz == 55.0);
  CHECK(e.oil_column_resonance->zeta == 0.08);
  REQUIRE(e.coulomb_friction);
  CHECK(e.coulomb_friction->loss_mm == 0.05);
  CHECK(e.coulomb_friction->v_smooth_mm_s == 2.0);
  REQUIRE(e.backlash);
  CHECK(e.backlash->gap_mm == 0.1);
  REQUIRE(e.servovalve_saturation);
  CHECK(e.servovalve_saturation->vmax_mm_per_s == 300.0);
  REQUIRE(e.sensor_noise);
  CHECK(e.sensor_noise->rms_y_mm == 0.002);
  CHECK(e.sensor_noise->rms_f_kN == 0.05);
  REQUIRE(e.current_lag);
  CHECK(e.current_lag->tau_ms == 20.0);
  REQUIRE(e.damper_scale);
  CHECK(e.damper_scale->scale == 1.2);
  CHECK(s.plant.unmodelled.ripple_mm == 0.05);
  CHECK(s.plant.unmodelled.ripple_hz == 37.0);
  CHECK(s.plant.unmodelled.stiffness_kN_per_mm == 0.5);
  CHECK(s.plant.damper.alpha_a == 0.12);
  CHECK(s.plant.damper.k1 == 0.01);
  CHECK(s.plant.damper.alpha_b == 0.55);  // the rest stays Table 3
  CHECK(s.plant.RigMode());

  // Round trip: ToToml writes every effect that is on, and reads back to the same text.
  const std::string written = rths::scenario::ToToml(s);
  CHECK(written.find("[plant.effects.oil_column_resonance]") != std::string::npos);
  const Scenario back = ParseScenario(written, "back.toml");
  CHECK(rths::scenario::ToToml(back) == written);
  REQUIRE(back.plant.effects.coulomb_friction);
  CHECK(back.plant.effects.coulomb_friction->v_smooth_mm_s == 2.0);
  CHECK(s.plant.load_coupling_same_sample);
  CHECK(back.plant.load_coupling_same_sample);
  CHECK(written.find("same_sample = true") != std::string::npos);
  CHECK(ParseScenario(std::string(kBase) + "[plant.effects.load_coupling]\ncompliance_mm_per_kN = 0.001\n", "d.toml")
            .plant.load_coupling_same_sample);  // the default: stable at any compliance
  CHECK_FALSE(ParseScenario(std::string(kBase) +
                                "[plant.effects.load_coupling]\ncompliance_mm_per_kN = 0.001\nsame_sample = false\n",
                            "d.toml")
                  .plant.load_coupling_same_sample);
  CHECK(back.plant.damper.k1 == 0.01);
  CHECK(back.plant.unmodelled.ripple_hz == 37.0);
}

TEST_CASE("scenario: no effect table -> the nominal plant, and ToToml writes no effect") {
  const Scenario s = ParseScenario(kBase, "plain.toml");
  CHECK(s.plant.effects.Empty());
  CHECK(s.plant.unmodelled.Empty());
  CHECK_FALSE(s.plant.RigMode());
  const std::string written = rths::scenario::ToToml(s);
  CHECK(written.find("[plant.effects") == std::string::npos);
  CHECK(ParseScenario(written, "back.toml").plant.effects.Empty());
  // Optional parameters keep the library's defaults.
  const Scenario o = ParseScenario(std::string(kBase) + "[plant.effects.oil_column_resonance]\nf_hz = 80\n", "o.toml");
  REQUIRE(o.plant.effects.oil_column_resonance);
  CHECK(o.plant.effects.oil_column_resonance->zeta == rths::models::OilColumnResonance{}.zeta);
}

TEST_CASE("scenario: a bad effect value names the file, the key and the allowed range") {
  struct Case {
    const char* table;
    const char* body;
    const char* key;
    const char* range;
  };
  const Case cases[] = {
      {"pure_delay", "tau_ms = 150", "plant.effects.pure_delay.tau_ms", "[0, 100]"},
      {"pure_delay", "tau_ms = -1", "plant.effects.pure_delay.tau_ms", "[0, 100]"},
      {"gain_error", "gain = 3", "plant.effects.gain_error.gain", "[0.5, 2]"},
      {"load_coupling", "compliance_mm_per_kN = 2", "plant.effects.load_coupling.compliance_mm_per_kN", "[-1, 1]"},
      {"oil_column_resonance", "f_hz = 1000", "plant.effects.oil_column_resonance.f_hz", "(0, 900)"},
      {"oil_column_resonance", "f_hz = 60\nzeta = 0", "plant.effects.oil_column_resonance.zeta", "(0, 2]"},
      {"coulomb_friction", "loss_mm = 11", "plant.effects.coulomb_friction.loss_mm", "[0, 10]"},
      {"coulomb_friction", "loss_mm = 1\nv_smooth_mm_s = 0", "plant.effects.coulomb_friction.v_smooth_mm_s",
       "(0, 1000]"},
      {"backlash", "gap_mm = -0.1", "plant.effects.backlash.gap_mm", "[0, 10]"},
      {"servovalve_saturation", "vmax_mm_per_s = 0", "plant.effects.servovalve_saturation.vmax_mm_per_s",
       "(0, 1000000000]"},
      {"sensor_noise", "rms_y_mm = 20", "plant.effects.sensor_noise.rms_y_mm", "[0, 10]"},
      {"sensor_noise", "rms_f_kN = -1", "plant.effects.sensor_noise.rms_f_kN", "[0, 100]"},
      {"current_lag", "tau_ms = 2000", "plant.effects.current_lag.tau_ms", "[0, 1000]"},
      {"damper_scale", "scale = 0.01", "plant.effects.damper_scale.scale", "[0.1, 10]"},
  };
  for (const Case& c : cases) {
    const std::string body = c.body;
    CAPTURE(body);
    const std::string msg = ErrorOf(std::string(kBase) + "[plant.effects." + c.table + "]\n" + c.body + "\n");
    CheckContains(msg, {"bad.toml", c.key, c.range});
  }
}

TEST_CASE("scenario: unknown effect name, unknown parameter, missing parameter, wrong plant kind") {
  CheckContains(ErrorOf(std::string(kBase) + "[plant.effects.pure_dealy]\ntau_ms = 1\n"),
                {"bad.toml", "plant.effects.pure_dealy", "unknown table", "pure_delay", "gain_error", "load_coupling",
                 "oil_column_resonance", "coulomb_friction", "backlash", "servovalve_saturation", "sensor_noise",
                 "current_lag", "damper_scale", "did you mean \"plant.effects.pure_delay\""});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.effects.backlash]\ngap = 1\n"),
                {"plant.effects.backlash.gap", "unknown key", "gap_mm"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.effects.backlash]\n"),
                {"plant.effects.backlash.gap_mm", "missing"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.effects.sensor_noise]\n"),
                {"plant.effects.sensor_noise.rms_y_mm", "missing"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.effects]\nbacklash = 0.1\n"),
                {"plant.effects.backlash", "expected a table"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant]\nkind = \"physical\"\n[plant.effects.gain_error]\ngain = 1.1\n"),
                {"bad.toml", "plant.effects", "rig mode needs plant.kind = \"linear\""});
  CheckContains(ErrorOf(std::string(kBase) + "[plant]\nkind = \"ideal\"\n[plant.unmodelled]\nstiffness_kN_per_mm = 1\n"),
                {"plant.unmodelled", "rig mode needs plant.kind = \"linear\""});
}

TEST_CASE("scenario: [plant.unmodelled] and [plant.damper] ranges") {
  CheckContains(ErrorOf(std::string(kBase) + "[plant.unmodelled]\nripple_mm = 0.1\n"),
                {"plant.unmodelled.ripple_hz", "(0, 1000)", "frequency"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.unmodelled]\nripple_mm = 0.1\nripple_hz = 1000\n"),
                {"plant.unmodelled.ripple_hz", "(0, 1000)"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.unmodelled]\nripple_mm = 11\nripple_hz = 10\n"),
                {"plant.unmodelled.ripple_mm", "[0, 10]"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.unmodelled]\nstiffness_kN_per_mm = 200\n"),
                {"plant.unmodelled.stiffness_kN_per_mm", "[-100, 100]"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.unmodelled]\nspring = 1\n"),
                {"plant.unmodelled.spring", "unknown key"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.damper]\nc0_a = 0\n"), {"bad.toml", "plant.damper.c0_a", "> 0"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.damper]\nn = 0.5\n"), {"plant.damper.n", ">= 1"});
  CheckContains(ErrorOf(std::string(kBase) + "[plant.damper]\nalpha = 0.5\n"),
                {"plant.damper.alpha", "unknown key"});
  // The damper table works with every plant kind.
  const Scenario s = ParseScenario(std::string(kBase) + "[plant]\nkind = \"physical\"\n[plant.damper]\nalpha_b = 0.6\n",
                                   "ok.toml");
  CHECK(s.plant.damper.alpha_b == 0.6);
}

// ---------------------------------------------------------------------------------------------
// Each effect's signature through MakeRig

namespace {

auto Zero() {
  return [](int) { return 0.0; };
}
auto Constant(double v) {
  return [v](int) { return v; };
}
auto Sine(double amp, double f_hz) {
  return [amp, f_hz](int k) { return amp * std::sin(2.0 * kPi * f_hz * k * kDt); };
}

/// The rig mode's rig behind MakeRig (REQUIREs that it is one).
rths::models::EffectRig* AsEffectRig(rths::models::Rig* rig) {
  auto* e = dynamic_cast<rths::models::EffectRig*>(rig);
  REQUIRE(e != nullptr);
  return e;
}

}  // namespace

TEST_CASE("rig mode: identity effects give the nominal linear rig bit for bit; nominal plants keep their rig") {
  PlantConfig nominal = LinearPlant();
  CHECK(dynamic_cast<rths::models::EffectRig*>(rths::models::MakeRig(nominal, kDt).get()) == nullptr);
  PlantConfig identity = LinearPlant();
  identity.effects.damper_scale = rths::models::DamperScale{1.0};
  identity.effects.current_lag = rths::models::CurrentLag{0.0};
  identity.effects.sensor_noise = rths::models::SensorNoise{0.0, 0.0};
  CHECK(dynamic_cast<rths::models::EffectRig*>(rths::models::MakeRig(identity, kDt).get()) != nullptr);
  // 2 Hz, 10 mm sine with the 0.5 Hz 0 / 2.5 A pulse (current dynamics on): y, f and i_c agree bit for bit.
  auto pulse = [](int k) { return std::fmod(k * kDt, 2.0) < 1.0 ? 0.0 : 2.5; };
  const Response a = Drive(nominal, 3000, Sine(10.0, 2.0), pulse);
  const Response b = Drive(identity, 3000, Sine(10.0, 2.0), pulse);
  CHECK(a.y == b.y);
  CHECK(a.f == b.f);
  CHECK(a.i == b.i);
  CHECK(Rms(a.f) > 1.0);  // the damper works
}

TEST_CASE("rig mode: pure_delay shifts the step response by tau") {
  PlantConfig p = LinearPlant();
  p.specimen = rths::models::Specimen::kNone;
  const Response nominal = Drive(p, 400, Constant(1.0), Zero());
  for (double tau_ms : {2.0, 3.3, 7.75}) {
    CAPTURE(tau_ms);
    PlantConfig d = p;
    d.effects.pure_delay = rths::models::PureDelay{tau_ms};
    const Response delayed = Drive(d, 400, Constant(1.0), Zero());
    const double shift_s = CrossingTimeS(delayed.y, 0.5) - CrossingTimeS(nominal.y, 0.5);
    // A fractional delay interpolates the step linearly over one sample: within half a step.
    CHECK(std::abs(shift_s - tau_ms * 1e-3) <= 0.26 * kDt);
    // Nothing moves before tau.
    CHECK(delayed.y[static_cast<std::size_t>(std::floor(tau_ms * 1e-3 / kDt))] == 0.0);
  }
}

TEST_CASE("rig mode: gain_error scales the DC response") {
  PlantConfig p = LinearPlant();
  const Response nominal = Drive(p, 4000, Constant(2.0), Zero());
  for (double gain : {0.8, 1.15}) {
    PlantConfig g = p;
    g.effects.gain_error = rths::models::GainError{gain};
    const Response scaled = Drive(g, 4000, Constant(2.0), Zero());
    CHECK(scaled.y.back() / nominal.y.back() == doctest::Approx(gain).epsilon(1e-9));
    CHECK(nominal.y.back() == doctest::Approx(2.0 * 1.6e7 / (151.7 * 1.061e5)).epsilon(1e-6));
  }
}

TEST_CASE("rig mode: backlash loses the gap at every reversal") {
  const double gap = 0.4;
  PlantConfig p = LinearPlant();
  p.effects.backlash = rths::models::Backlash{gap};
  auto rig = rths::models::MakeRig(p, kDt);
  auto* e = AsEffectRig(rig.get());
  double x_max = -1e9, x_min = 1e9, y_max = -1e9, y_min = 1e9;
  int held = 0;  // samples after the top reversal during which y holds
  double y_prev = 0.0;
  for (int k = 0; k < 4000; ++k) {  // 1 Hz, 5 mm sine: two periods
    rig->Step(Sine(5.0, 1.0)(k), 0.0);
    if (k >= 1000) {  // after the first quarter period (the play starts centred)
      x_max = std::max(x_max, e->actuator_x_mm());
      x_min = std::min(x_min, e->actuator_x_mm());
      y_max = std::max(y_max, rig->y_mm());
      y_min = std::min(y_min, rig->y_mm());
    }
    if (k >= 2000 && k < 3000 && rig->y_mm() == y_prev) ++held;
    y_prev = rig->y_mm();
  }
  CHECK((x_max - x_min) - (y_max - y_min) == doctest::Approx(gap).epsilon(1e-9));
  CHECK(x_max - y_max == doctest::Approx(gap / 2).epsilon(1e-9));
  // Around the reversal at the top, y holds while x comes back by the gap: 5 (1 - cos(w t)) = 0.4
  // -> t = 64 ms, about 128 samples.
  CHECK(held > 100);
  CHECK(held < 160);
}

TEST_CASE("rig mode: servovalve_saturation bounds |dy/dt| by vmax") {
  const double vmax = 150.0;
  PlantConfig p = LinearPlant();
  p.effects.servovalve_saturation = rths::models::ServovalveSaturation{vmax};
  const Response r = Drive(p, 2000, Constant(20.0), Zero());
  double v_peak = 0.0;
  for (std::size_t k = 1; k < r.y.size(); ++k) v_peak = std::max(v_peak, std::abs(r.y[k] - r.y[k - 1]) / kDt);
  CHECK(v_peak <= vmax * (1 + 1e-9));
  CHECK(v_peak >= vmax * (1 - 1e-9));  // binding: the nominal step is much faster
  const Response nominal = Drive(LinearPlant(), 2000, Constant(20.0), Zero());
  double v_nominal = 0.0;
  for (std::size_t k = 1; k < nominal.y.size(); ++k)
    v_nominal = std::max(v_nominal, std::abs(nominal.y[k] - nominal.y[k - 1]) / kDt);
  CHECK(v_nominal > 5 * vmax);
  CHECK(r.y.back() == doctest::Approx(nominal.y.back()).epsilon(1e-6));  // it gets there in the end
}

TEST_CASE("rig mode: damper_scale scales the force, unmodelled stiffness adds k y") {
  PlantConfig p = LinearPlant();
  const Response nominal = Drive(p, 2000, Sine(10.0, 1.5), Constant(1.0));
  PlantConfig s = p;
  s.effects.damper_scale = rths::models::DamperScale{0.7};
  const Response scaled = Drive(s, 2000, Sine(10.0, 1.5), Constant(1.0));
  CHECK(scaled.y == nominal.y);
  for (std::size_t k = 0; k < nominal.f.size(); k += 97) CHECK(scaled.f[k] == doctest::Approx(0.7 * nominal.f[k]));
  CHECK(Rms(nominal.f) > 10.0);
  PlantConfig k = p;
  k.unmodelled.stiffness_kN_per_mm = 2.0;
  const Response spring = Drive(k, 2000, Sine(10.0, 1.5), Constant(1.0));
  for (std::size_t j = 0; j < nominal.f.size(); j += 97)
    CHECK(spring.f[j] - nominal.f[j] == doctest::Approx(2.0 * nominal.y[j]).epsilon(1e-9).scale(1.0));
}

TEST_CASE("rig mode: current_lag delays the force response to a current step by about tau ln 2") {
  // Constant-velocity motion (a 40 mm/s ramp), the current steps 0 -> 2.5 A at t = 0.5 s; without
  // current dynamics the nominal force jumps at once, the lagged one follows 1 - exp(-t / tau).
  PlantConfig p = LinearPlant();
  p.current_dynamics = false;
  auto ramp = [](int k) { return 40.0 * k * kDt; };
  auto step = [](int k) { return k >= 1000 ? 2.5 : 0.0; };
  const Response nominal = Drive(p, 1600, ramp, step);
  const double f_lo = nominal.f[999], f_hi = nominal.f[1500];
  REQUIRE(f_hi > 3 * f_lo);
  auto half_time = [&](const Response& r) { return CrossingTimeS(r.f, 0.5 * (f_lo + f_hi)) - 1000 * kDt; };
  for (double tau_ms : {10.0, 30.0}) {
    CAPTURE(tau_ms);
    PlantConfig l = p;
    l.effects.current_lag = rths::models::CurrentLag{tau_ms};
    const Response lagged = Drive(l, 1600, ramp, step);
    CHECK(lagged.f[999] == nominal.f[999]);
    // The effective current is the first-order lag's (exact ZOH, within a step).
    const int k_tau = 1000 + static_cast<int>(std::lround(tau_ms * 1e-3 / kDt));
    CHECK(lagged.i[k_tau] == doctest::Approx(2.5 * (1 - std::exp(-1.0))).epsilon(0.03));
    const double delay = half_time(lagged) - half_time(nominal);
    CHECK(delay == doctest::Approx(tau_ms * 1e-3 * std::log(2.0)).epsilon(0.2));
    CHECK(lagged.f[1500] == doctest::Approx(f_hi).epsilon(0.01));
  }
}

TEST_CASE("rig mode: load_coupling makes y lower by c f, coulomb_friction by loss against the motion") {
  // same_sample = false: the previous sample's force, y_k = x_k - c f_{k-1}, exactly.
  // Stable while c (alpha A + 2 B / dt) < 1: at 2.5 A, 0.0004 x 1420 = 0.57.
  {
    const double c = 0.0004;
    PlantConfig p = LinearPlant();
    p.effects.load_coupling = rths::models::LoadCoupling{c};
    p.load_coupling_same_sample = false;
    auto rig = rths::models::MakeRig(p, kDt);
    auto* e = AsEffectRig(rig.get());
    double f_prev = e->true_f_kN(), peak_shift = 0.0;
    for (int k = 0; k < 3000; ++k) {
      rig->Step(Sine(10.0, 1.0)(k), 2.5);
      CHECK(rig->y_mm() == doctest::Approx(e->actuator_x_mm() - c * f_prev).epsilon(0).scale(1).epsilon(1e-12));
      peak_shift = std::max(peak_shift, std::abs(rig->y_mm() - e->actuator_x_mm()));
      f_prev = e->true_f_kN();
    }
    CHECK(peak_shift > 0.04);  // 2.5 A: forces above 100 kN
  }
  // same_sample: y_k = x_k - c f_k with the force of the same sample (solved in the step), stable
  // even where the explicit form diverges (c (alpha A + 2 B / dt) = 0.005 x 1420 > 1 at 2.5 A).
  for (double c : {0.0004, 0.005}) {
    CAPTURE(c);
    PlantConfig p = LinearPlant();
    p.effects.load_coupling = rths::models::LoadCoupling{c};
    p.load_coupling_same_sample = true;
    auto rig = rths::models::MakeRig(p, kDt);
    auto* e = AsEffectRig(rig.get());
    double peak_shift = 0.0, peak_f = 0.0;
    for (int k = 0; k < 3000; ++k) {
      rig->Step(Sine(10.0, 1.0)(k), 2.5);
      CHECK(rig->y_mm() == doctest::Approx(e->actuator_x_mm() - c * e->true_f_kN()).epsilon(0).scale(1).epsilon(1e-7));
      peak_shift = std::max(peak_shift, std::abs(rig->y_mm() - e->actuator_x_mm()));
      peak_f = std::max(peak_f, std::abs(e->true_f_kN()));
    }
    CHECK(peak_f > 100.0);  // 2.5 A
    CHECK(peak_shift == doctest::Approx(c * peak_f).epsilon(0.05));
    CHECK(e->unconverged_steps() == 0);
  }
  {  // the explicit form at c = 0.005 does diverge (the reason for same_sample)
    PlantConfig p = LinearPlant();
    p.effects.load_coupling = rths::models::LoadCoupling{0.005};
    p.load_coupling_same_sample = false;
    auto rig = rths::models::MakeRig(p, kDt);
    bool diverged = false;
    try {
      for (int k = 0; k < 3000 && !diverged; ++k) {
        rig->Step(Sine(10.0, 1.0)(k), 2.5);
        diverged = !(std::abs(rig->f_kN()) < 1e4);
      }
    } catch (const rths::Error&) {
      diverged = true;  // CVODE gives up
    }
    CHECK(diverged);
  }

  PlantConfig fr = LinearPlant();
  fr.specimen = rths::models::Specimen::kNone;
  fr.effects.coulomb_friction = rths::models::CoulombFriction{0.3, 0.5};
  auto rf = rths::models::MakeRig(fr, kDt);
  auto* ef = AsEffectRig(rf.get());
  auto triangle = [](int k) {  // +-20 mm/s, reversing every second
    const double t = k * kDt;
    return std::fmod(t, 2.0) < 1.0 ? 20.0 * std::fmod(t, 2.0) : 20.0 * (2.0 - std::fmod(t, 2.0));
  };
  for (int k = 0; k < 4000; ++k) {
    rf->Step(triangle(k), 0.0);
    if (k == 500 || k == 1500) CHECK(rf->y_mm() - ef->actuator_x_mm() == doctest::Approx(-0.3).epsilon(1e-6));
    if (k == 2500 || k == 3500) CHECK(rf->y_mm() - ef->actuator_x_mm() == doctest::Approx(0.3).epsilon(1e-6));
  }
}

TEST_CASE("rig mode: oil_column_resonance amplifies a sine at f_hz by about 1 / (2 zeta)") {
  const double f_hz = 60.0, zeta = 0.05;
  PlantConfig p = LinearPlant();
  p.specimen = rths::models::Specimen::kNone;
  PlantConfig o = p;
  o.effects.oil_column_resonance = rths::models::OilColumnResonance{f_hz, zeta};
  auto ratio = [&](double f) {
    const Response a = Drive(p, 3000, Sine(0.1, f), Zero());
    const Response b = Drive(o, 3000, Sine(0.1, f), Zero());
    return Rms(b.y, 1000) / Rms(a.y, 1000);  // after 0.5 s (the mode decays in 1/(zeta w) = 53 ms)
  };
  CHECK(ratio(f_hz) == doctest::Approx(1.0 / (2 * zeta)).epsilon(0.05));
  CHECK(ratio(f_hz / 4) == doctest::Approx(1.0 / (1.0 - 1.0 / 16)).epsilon(0.02));
  CHECK(ratio(2 * f_hz) == doctest::Approx(1.0 / 3.0).epsilon(0.05));
}

TEST_CASE("rig mode: sensor noise and ripple are seeded: same seed bit-identical, another seed different") {
  PlantConfig p = LinearPlant();
  p.effects.sensor_noise = rths::models::SensorNoise{0.01, 0.2};
  p.unmodelled.ripple_mm = 0.05;
  p.unmodelled.ripple_hz = 37.0;
  p.noise_seed = 11;
  const Response a = Drive(p, 10000, Sine(5.0, 2.0), Constant(0.5));
  const Response b = Drive(p, 10000, Sine(5.0, 2.0), Constant(0.5));
  CHECK(a.y == b.y);
  CHECK(a.f == b.f);
  PlantConfig q = p;
  q.noise_seed = 12;
  const Response c = Drive(q, 10000, Sine(5.0, 2.0), Constant(0.5));
  CHECK(a.y != c.y);
  CHECK(a.f != c.f);
  // The measured minus the true signals: noise of the given rms, plus the ripple on y.
  auto rig = rths::models::MakeRig(p, kDt);
  auto* e = AsEffectRig(rig.get());
  std::vector<double> ny, nf;
  for (int k = 0; k < 10000; ++k) {
    rig->Step(Sine(5.0, 2.0)(k), 0.5);
    const double t = (k + 1) * kDt;
    ny.push_back(rig->y_mm() - e->true_y_mm() - 0.05 * std::sin(2 * kPi * 37.0 * t));
    nf.push_back(rig->f_kN() - e->true_f_kN());
  }
  CHECK(Rms(ny) == doctest::Approx(0.01).epsilon(0.05));
  CHECK(Rms(nf) == doctest::Approx(0.2).epsilon(0.05));
  // Noise off: the ripple alone, exactly.
  PlantConfig r = LinearPlant();
  r.unmodelled.ripple_mm = 0.05;
  r.unmodelled.ripple_hz = 37.0;
  auto rr = rths::models::MakeRig(r, kDt);
  auto* er = AsEffectRig(rr.get());
  for (int k = 0; k < 200; ++k) {
    rr->Step(1.0, 0.0);
    CHECK(rr->y_mm() - er->true_y_mm() == doctest::Approx(0.05 * std::sin(2 * kPi * 37.0 * (k + 1) * kDt)).epsilon(0).scale(1).epsilon(1e-12));
  }
}

TEST_CASE("rig mode: Step allocates nothing, with every effect on") {
  PlantConfig p = LinearPlant();
  p.effects.pure_delay = rths::models::PureDelay{3.7};
  p.effects.gain_error = rths::models::GainError{1.05};
  p.effects.load_coupling = rths::models::LoadCoupling{0.0004};
  p.effects.oil_column_resonance = rths::models::OilColumnResonance{70.0, 0.1};
  p.effects.coulomb_friction = rths::models::CoulombFriction{0.05, 0.5};
  p.effects.backlash = rths::models::Backlash{0.05};
  p.effects.servovalve_saturation = rths::models::ServovalveSaturation{400.0};
  p.effects.sensor_noise = rths::models::SensorNoise{0.005, 0.1};
  p.effects.current_lag = rths::models::CurrentLag{15.0};
  p.effects.damper_scale = rths::models::DamperScale{1.1};
  p.unmodelled.ripple_mm = 0.02;
  p.unmodelled.ripple_hz = 45.0;
  p.unmodelled.stiffness_kN_per_mm = 0.3;
  for (bool same_sample : {false, true}) {
    CAPTURE(same_sample);
    p.load_coupling_same_sample = same_sample;
    auto rig = rths::models::MakeRig(p, kDt);
    rig->Step(0.0, 0.0);  // first step outside the count
    const long before = rths_test::AllocationCount();
    for (int k = 1; k < 500; ++k) rig->Step(Sine(5.0, 3.0)(k), (k / 100) % 2 ? 2.5 : 0.0);
    CHECK(rths_test::AllocationCount() == before);
    CHECK(std::isfinite(rig->y_mm()));
    CHECK(std::abs(rig->f_kN()) > 0.0);
  }
}

TEST_CASE("rig mode: MakeRig refuses effects on a physical or ideal plant") {
  for (const char* kind : {"physical", "ideal"}) {
    PlantConfig p;
    p.kind = rths::ParseName(rths::models::kPlantKindNames, kind, "kind");
    p.effects.gain_error = rths::models::GainError{1.1};
    try {
      rths::models::MakeRig(p, kDt);
      FAIL("expected an rths::Error");
    } catch (const rths::Error& e) {
      CheckContains(e.what(), {"plant.effects", "rig mode needs plant.kind = \"linear\""});
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Through the lockstep, and out as a rig record

TEST_CASE("rig mode: a lockstep run (memq) with effects on, then its rig record (rths record's path)") {
  const fs::path dir = rths_test::TempDir("rig_mode_run");
  // The example scenario, shortened to 2.5 s (a record needs at least 2 s).
  const fs::path example = fs::path(RTHS_SOURCE_DIR) / "scenarios/rig_mode_example.toml";
  Scenario s = rths::scenario::LoadScenario(example.string());
  REQUIRE(s.plant.effects.pure_delay);
  REQUIRE(s.plant.effects.damper_scale);
  s.run.duration_s = 2.5;
  const fs::path file = rths_test::WriteScenario(dir, rths::scenario::ToToml(s));
  s = rths::scenario::LoadScenario(file.string());
  const fs::path out = dir / "run";
  fs::create_directories(out);
  const auto r = rths_test::RunMemq({s}, out);
  for (const auto& e : r.errors) CAPTURE(e);
  REQUIRE(r.code == 0);

  const rths::io::RunLog log = rths::io::ReadRunLog((out / "log.lcm").string());
  REQUIRE(log.CompleteSteps() == s.steps());
  rths::io::RigRecord rec = rths::io::RigRecordFromRunLog(log, (out / "log.lcm").string());
  rec.metadata.emplace_back("producer", "rths record");
  const fs::path csv = dir / "record.csv";
  rths::io::WriteRigRecord(rec, csv.string());
  const rths::io::RigRecord back = rths::io::ReadRigRecord(csv.string());
  CHECK(back.size() == static_cast<std::size_t>(s.steps()));
  CHECK(back.dt_s == s.run.dt_s);
  CHECK(back.has_r());
  CHECK(back.Meta("producer") == "rths record");
  CHECK(back.warnings.empty());
  // Written with 10 significant digits: the values come back to that precision.
  for (std::size_t k = 0; k < back.size(); k += 331) {
    CHECK(back.u_mm[k] == doctest::Approx(log.command[k].u_mm).epsilon(1e-9).scale(1e-6));
    CHECK(back.y_mm[k] == doctest::Approx(log.measured[k].y_mm).epsilon(1e-9).scale(1e-6));
    CHECK(back.f_kN[k] == doctest::Approx(log.measured[k].f_kN).epsilon(1e-9).scale(1e-6));
    CHECK(back.i_A[k] == log.current[k].i_cmd_A);
  }
  // The pulse current reaches the record, and the damper answers with force.
  CHECK(*std::max_element(back.i_A.begin(), back.i_A.end()) == 2.5);
  CHECK(Rms(back.f_kN) > 5.0);

  // The effects are in the loop: replaying the record's command through the rig model reproduces
  // the measured y and f to the sensor noise, and the nominal linear rig does not.
  auto replay = [&](const PlantConfig& plant) {
    auto rig = rths::models::MakeRig(plant, s.run.dt_s);
    double ey = 0.0, ef = 0.0;
    for (std::size_t k = 1; k < back.size(); ++k) {
      rig->Step(log.command[k - 1].u_mm, log.current[k - 1].i_cmd_A);
      ey += std::pow(rig->y_mm() - log.measured[k].y_mm, 2);
      ef += std::pow(rig->f_kN() - log.measured[k].f_kN, 2);
    }
    const double n = static_cast<double>(back.size() - 1);
    return std::pair{std::sqrt(ey / n), std::sqrt(ef / n)};
  };
  PlantConfig quiet = s.plant;  // the same rig, without the baseline noise (the participant adds it)
  const auto [ey, ef] = replay(quiet);
  CHECK(ey == doctest::Approx(s.plant.noise_y_mm_rms).epsilon(0.1));
  CHECK(ef == doctest::Approx(s.plant.noise_f_kN_rms).epsilon(0.1));
  PlantConfig nominal = s.plant;
  nominal.effects = {};
  const auto [ny, nf] = replay(nominal);
  CHECK(ny > 5 * ey);
  CHECK(nf > 5 * ef);
}

TEST_CASE("rths record: writes RUN_DIR/record.csv; a missing run folder or log exits 2") {
  const std::string bin = std::string(RTHS_BIN_DIR) + "/rths-record";
  rths_test::RequireBuilt("rths-record");
  const fs::path dir = rths_test::TempDir("record_cli");
  CHECK(std::system((bin + " " + (dir / "nothing").string() + " > /dev/null 2>&1").c_str()) == 2 * 256);
  CHECK(std::system((bin + " " + dir.string() + " > /dev/null 2>&1").c_str()) == 2 * 256);  // no log.lcm
  const fs::path file = rths_test::WriteScenario(dir, R"(
[run]
dt_s = 0.0005
duration_s = 2.0
[structure]
mode = "predefined"
[structure.desired]
band_hz = 5.0
rms_mm = 1.0
[plant]
specimen = "none"
[plant.effects.gain_error]
gain = 0.9
)");
  const Scenario s = rths::scenario::LoadScenario(file.string());
  const fs::path out = dir / "run";
  fs::create_directories(out);
  REQUIRE(rths_test::RunMemq({s}, out).code == 0);
  REQUIRE(std::system((bin + " " + out.string() + " > /dev/null 2>&1").c_str()) == 0);
  const rths::io::RigRecord rec = rths::io::ReadRigRecord((out / "record.csv").string());
  CHECK(rec.size() == 4000);
  CHECK(rec.Meta("producer") == "rths record");
  CHECK(Rms(rec.y_mm) == doctest::Approx(0.9 * Rms(rec.u_mm)).epsilon(0.05));  // the gain error shows
  const fs::path other = dir / "elsewhere.csv";
  REQUIRE(std::system((bin + " " + out.string() + " --out " + other.string() + " > /dev/null 2>&1").c_str()) == 0);
  CHECK(rths::io::ReadRigRecord(other.string()).size() == 4000);
}
