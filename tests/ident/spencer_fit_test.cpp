// The current-dependent MR damper fit (ident/spencer_fit.h) and what it needs: the first-order
// control filter of the current driver, the random_pulse current schedule, voltage records, the
// velocity cut-off from the record's band, and the model file read back by the scenario parser
// and by the diagnosis. The recovery test fits a record made by the plant's rig mode (models::
// MakeRig with the sensor_noise effect) with a pulsed current of random levels.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/channel_models.h"
#include "ident/damper_fit.h"
#include "ident/fit_advice.h"
#include "ident/plausible_range.h"
#include "ident/spencer_fit.h"
#include "io/rig_record.h"
#include "io/utfsm.h"
#include "models/current_driver.h"
#include "models/rig.h"
#include "control/current_schedule.h"
#include "scenario/scenario.h"
#include "signal/blwn.h"
#include "test_support.h"

namespace {

namespace m = rths::models;
using rths::ident::ControlFilter;

/// A rig-mode record: the linear plant ("avg"), the Table 3 damper, the first-order current
/// filter with eta, sensor noise as a rig-mode effect, u = BLWN, i = random pulses.
rths::io::RigRecord RigModeRecord(double eta_1_s, double dt, double duration_s, double band_hz, double rms_mm,
                                  std::uint64_t seed, const std::string& name, double noise_y_mm = 0.001,
                                  double noise_f_kN = 0.02, double k0_kN_mm = -1.0) {
  m::PlantConfig plant;
  if (k0_kN_mm >= 0.0) plant.damper.k0 = k0_kN_mm;
  plant.kind = m::PlantKind::kLinear;
  plant.current_driver.kind = m::CurrentFilter::kFirstOrder;
  plant.current_driver.eta_1_s = eta_1_s;
  plant.effects.sensor_noise = m::SensorNoise{noise_y_mm, noise_f_kN};
  plant.noise_seed = seed + 100;
  auto rig = m::MakeRig(plant, dt);
  rths::control::SemiactiveConfig sa;
  sa.mode = rths::control::SemiactiveMode::kRandomPulse;
  sa.pulse_hz = 2.0;
  sa.pulse_duty = 0.6;
  sa.pulse_seed = seed;
  const rths::control::CurrentSchedule schedule(sa, dt);
  const auto n = static_cast<std::size_t>(std::llround(duration_s / dt));
  const auto u = rths::signal::Blwn(band_hz, rms_mm, dt, n, seed, 1.0);
  rths::io::RigRecord rec;
  rec.dt_s = dt;
  rec.source = name;
  for (std::size_t k = 0; k < n; ++k) {
    const double i = schedule.At(static_cast<std::int64_t>(k));
    rec.t_s.push_back(static_cast<double>(k) * dt);
    rec.u_mm.push_back(u[k]);
    rec.y_mm.push_back(rig->y_mm());
    rec.f_kN.push_back(rig->f_kN());
    rec.i_A.push_back(i);
    rig->Step(u[k], i);
  }
  return rec;
}

}  // namespace

TEST_CASE("first-order current filter: H(s) = eta / (s + eta), exact step response, continuous on a jump") {
  m::CurrentDriverParams p;
  p.kind = m::CurrentFilter::kFirstOrder;
  p.eta_1_s = 150.0;
  const double dt = 1.0 / 3000.0;
  const auto d = m::CurrentDriver::Make(p, dt);
  CHECK(d.DcGain() == doctest::Approx(1.0).epsilon(1e-14));
  const auto h = d.FrequencyResponse(150.0 / (2.0 * std::numbers::pi));  // at the corner: 1 / (1 + j)
  CHECK(std::abs(h) == doctest::Approx(1.0 / std::sqrt(2.0)).epsilon(1e-12));
  auto s = m::SteadyState(0.0);
  for (int k = 0; k < 30; ++k) {
    CHECK(m::EffectiveCurrentA(d, s) == doctest::Approx(2.0 * (1.0 - std::exp(-150.0 * k * dt))).epsilon(1e-12));
    m::Step(d, &s, 2.0);
  }
  // Closed form inside a step, and the same as DriverOutputA (no separate Eq. 40 stage).
  CHECK(m::EffectiveCurrentAt(d, s, 0.5 * dt) ==
        doctest::Approx(2.0 * (1.0 - std::exp(-150.0 * 30.5 * dt))).epsilon(1e-12));
  CHECK(m::DriverOutputA(d, s) == m::EffectiveCurrentA(d, s));
  p.eta_1_s = 0.0;
  CHECK_THROWS_AS(m::CurrentDriver::Make(p, dt), rths::Error);
}

TEST_CASE("random_pulse: a pure function of k, levels spread over [0, max], off between pulses") {
  rths::control::SemiactiveConfig sa;
  sa.mode = rths::control::SemiactiveMode::kRandomPulse;
  sa.max_current_A = 2.5;
  sa.pulse_hz = 2.0;
  sa.pulse_duty = 0.5;
  const double dt = 0.001;
  const rths::control::CurrentSchedule a(sa, dt), b(sa, dt);
  double lo = 9, hi = -9;
  for (std::int64_t k = 0; k < 20000; ++k) {
    const double i = a.At(k);
    REQUIRE(i == b.At(k));
    CHECK(i >= 0.0);
    CHECK(i < 2.5);
    if (k % 500 >= 250) CHECK(i == 0.0);
    if (k % 500 == 0) lo = std::min(lo, i), hi = std::max(hi, i);
    if (k % 500 > 0 && k % 500 < 250) CHECK(i == a.At(k - 1));  // one level per pulse
  }
  CHECK(lo < 0.5);
  CHECK(hi > 2.0);
  sa.pulse_seed = 2;
  CHECK(rths::control::CurrentSchedule(sa, dt).At(0) != a.At(0));
}

TEST_CASE("[plant.current_driver] and random_pulse are read, written back and range-checked") {
  const auto dir = rths_test::TempDir("spencer_scenario");
  const auto sc = rths::scenario::LoadScenario(
      rths_test::WriteScenario(dir, "[run]\nduration_s = 0.5\n[plant.current_driver]\nkind = \"first_order\"\n"
                                    "eta_1_s = 120.0\n[semiactive]\nmode = \"random_pulse\"\npulse_seed = 9\n")
          .string());
  CHECK(sc.plant.current_driver.kind == m::CurrentFilter::kFirstOrder);
  CHECK(sc.plant.current_driver.eta_1_s == 120.0);
  CHECK(sc.semiactive.mode == rths::control::SemiactiveMode::kRandomPulse);
  CHECK(sc.semiactive.pulse_seed == 9u);
  const auto again = rths::scenario::LoadScenario(rths_test::WriteScenario(dir, rths::scenario::ToToml(sc)).string());
  CHECK(again.plant.current_driver == sc.plant.current_driver);
  CHECK(again.semiactive == sc.semiactive);
  try {
    rths::scenario::LoadScenario(
        rths_test::WriteScenario(dir, "[plant.current_driver]\nkind = \"first_order\"\neta_1_s = -3.0\n").string());
    FAIL("a negative eta was accepted");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("plant.current_driver.eta_1_s") != std::string::npos);
  }
}

TEST_CASE("v_V: a voltage column is read, written back, and drives the fit's input") {
  rths::io::RigRecord rec;
  rec.dt_s = 0.001;
  for (int k = 0; k < 2500; ++k) {
    rec.t_s.push_back(k * 0.001);
    rec.u_mm.push_back(std::sin(k * 0.01));
    rec.y_mm.push_back(std::sin(k * 0.01));
    rec.f_kN.push_back(0.1 * std::cos(k * 0.01));
    rec.v_V.push_back(k % 500 < 250 ? 5.0 : 0.0);
  }
  const auto dir = rths_test::TempDir("spencer_vV");
  const auto path = (dir / "v.csv").string();
  rths::io::WriteRigRecord(rec, path);
  const auto back = rths::io::ReadRigRecord(path);
  CHECK(back.i_A.empty());
  REQUIRE(back.v_V.size() == rec.size());
  CHECK(back.v_V[0] == 5.0);
  CHECK(back.Command() == back.v_V);
  CHECK(rths::ident::ControlInput(back, true)[300] == 0.0);
  CHECK_THROWS_AS(rths::ident::ControlInput(back, false), rths::Error);
  // Neither i_A nor v_V: refused, naming both.
  { std::ofstream(path) << "# rths rig record v1\n# dt_s: 0.001\nt_s,u_mm,y_mm,f_kN\n0,0,0,0\n"; }
  try {
    rths::io::ReadRigRecord(path);
    FAIL("a record without a damper command was accepted");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("v_V") != std::string::npos);
  }
}

TEST_CASE("VelocityCutoffHz follows the displacement's band: 50 Hz for slow tests, higher for wide-band ones") {
  const double dt = 1.0 / 3000.0;
  const std::size_t n = 3 * 3000 * 4;
  rths::io::RigRecord slow, wide;
  slow.dt_s = wide.dt_s = dt;
  std::mt19937_64 gen(5);
  std::normal_distribution<double> noise(0.0, 0.002);  // sensor noise [mm]
  const auto a = rths::signal::Blwn(5.0, 2.0, dt, n, 3, 1.0);
  const auto b = rths::signal::Blwn(50.0, 2.0, dt, n, 4, 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    slow.t_s.push_back(k * dt);
    wide.t_s.push_back(k * dt);
    slow.y_mm.push_back(a[k] + noise(gen));
    wide.y_mm.push_back(b[k] + noise(gen));
  }
  CHECK(rths::ident::VelocityCutoffHz(slow) == doctest::Approx(50.0));
  const double fw = rths::ident::VelocityCutoffHz(wide);
  CHECK(fw > 150.0);  // 4 x a velocity band edge of about 50-60 Hz
  CHECK(fw < 400.0);
}

TEST_CASE("FitSpencer recovers Eqs. 35-39 and eta from a rig-mode record with a pulsed current") {
  const double eta = 120.0, dt = 1.0 / 3000.0;
  const std::vector<rths::io::RigRecord> train = {RigModeRecord(eta, dt, 20.0, 20.0, 8.0, 5, "train")};
  const auto test = RigModeRecord(eta, dt, 6.0, 8.0, 4.0, 6, "test");
  rths::ident::DamperFitOptions o;
  o.input = rths::ident::DamperInput::kCurrent;
  const auto fit = rths::ident::FitSpencer(train, o);
  MESSAGE(fit.Report());
  const auto t = m::MrDamperParams::Table3();
  const auto& p = fit.params;
  const std::pair<double, double> pairs[] = {{p.alpha_a, t.alpha_a}, {p.alpha_b, t.alpha_b}, {p.alpha_c, t.alpha_c},
                                             {p.c0_a, t.c0_a},       {p.c0_b, t.c0_b},       {p.c0_c, t.c0_c},
                                             {p.c1_a, t.c1_a},       {p.c1_b, t.c1_b},       {p.c1_c, t.c1_c},
                                             {p.beta_a, t.beta_a},   {p.beta_b, t.beta_b},   {p.beta_c, t.beta_c},
                                             {p.gamma_a, t.gamma_a}, {p.gamma_b, t.gamma_b}, {p.gamma_c, t.gamma_c}};
  int i = 0;
  for (const auto& [got, want] : pairs) {
    CAPTURE(i++);
    CHECK(got == doctest::Approx(want).epsilon(0.03));
  }
  CHECK(fit.driver.kind == m::CurrentFilter::kFirstOrder);
  CHECK(fit.driver.eta_1_s == doctest::Approx(eta).epsilon(0.03));
  CHECK(fit.records[0].nrmse_f_pct < 2.0);
  const auto held = rths::ident::ScoreSpencer(fit.params, fit.driver, fit.filter, test, false);
  CHECK(held.nrmse_f_pct < 2.0);

  // Without the filter the same record fits worse: the filter is a real part of the model.
  o.filter = ControlFilter::kNone;
  o.max_iterations = 40;
  const auto none = rths::ident::FitSpencer(train, o);
  CHECK(none.records[0].nrmse_f_pct > fit.records[0].nrmse_f_pct);

  // The model file: the scenario parser and the diagnosis read the same model back.
  const auto dir = rths_test::TempDir("spencer_model");
  const std::string toml = rths::ident::SpencerModelToml(fit, "test");
  const auto path = (dir / "damper.toml").string();
  { std::ofstream(path) << toml; }
  const auto sc = rths::scenario::LoadScenario(path);
  CHECK(sc.plant.damper.c1_c == doctest::Approx(p.c1_c).epsilon(1e-9));
  CHECK(sc.plant.current_driver.kind == m::CurrentFilter::kFirstOrder);
  CHECK(sc.plant.current_driver.eta_1_s == doctest::Approx(fit.driver.eta_1_s).epsilon(1e-9));
  CHECK(sc.plant.current_dynamics);
  const auto model = rths::diagnosis::LoadModel(path);
  CHECK(model.current_driver == sc.plant.current_driver);
  CHECK(model.damper == sc.plant.damper);
}

TEST_CASE("FitSpencer: bad input is refused with the reason") {
  const double dt = 0.001;
  rths::io::RigRecord rec;
  rec.dt_s = dt;
  rec.source = "constant.csv";
  for (int k = 0; k < 3000; ++k) {
    rec.t_s.push_back(k * dt);
    rec.u_mm.push_back(std::sin(k * 0.01));
    rec.y_mm.push_back(std::sin(k * 0.01));
    rec.f_kN.push_back(std::cos(k * 0.01));
    rec.i_A.push_back(1.0);
  }
  try {
    rths::ident::FitSpencer({rec}, {.input = rths::ident::DamperInput::kCurrent});
    FAIL("a constant current was accepted");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("--current") != std::string::npos);
  }
  // No v_V column:
  CHECK_THROWS_AS(rths::ident::FitSpencer({rec}, {.input = rths::ident::DamperInput::kVoltage}), rths::Error);
  rths::ident::DamperFitOptions o;
  o.threads = -1;
  CHECK_THROWS_AS(rths::ident::FitSpencer({rec}, o), rths::Error);
}


TEST_CASE("rths identify --damper without --current: the fit from a CSV record, a model file that loads") {
  const auto dir = rths_test::TempDir("spencer_cli");
  const auto rec = RigModeRecord(150.0, 0.0005, 20.0, 20.0, 8.0, 11, "cli");
  const auto csv = (dir / "rec.csv").string(), model = (dir / "model.toml").string(),
             log = (dir / "out.txt").string();
  rths::io::WriteRigRecord(rec, csv);
  const std::string cmd =
      fmt::format("{}/rths-identify --damper {} --out {} > {} 2>&1", RTHS_BIN_DIR, csv, model, log);
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  const auto sc = rths::scenario::LoadScenario(model);
  CHECK(sc.plant.current_driver.kind == m::CurrentFilter::kFirstOrder);
  CHECK(sc.plant.current_driver.eta_1_s == doctest::Approx(150.0).epsilon(0.03));
  CHECK(sc.plant.damper.alpha_b == doctest::Approx(0.55).epsilon(0.03));
  // The file says how the fit ended (ident/fit_status.h).
  const std::string text = rths_test::Slurp(model);
  CHECK(text.find("[fit]\nstatus = \"ok\"") != std::string::npos);
  CHECK(text.find("FIT FAILED") == std::string::npos);
  // --current on a record whose current varies is refused (exit 2), naming the record.
  const int bad = std::system(
      fmt::format("{}/rths-identify --damper {} --current 1.0 > {} 2>&1", RTHS_BIN_DIR, csv, log).c_str());
  CHECK(WEXITSTATUS(bad) == 2);
}

TEST_CASE("fit status: a fit stopped early, and a parameter on a bound of its range, say so everywhere") {
  const double dt = 0.0005;
  const auto rec = RigModeRecord(150.0, dt, 10.0, 12.0, 6.0, 21, "status");
  SUBCASE("stopped early: not converged, FIT FAILED in the file, [fit] status failed, the file still loads") {
    rths::ident::DamperFitOptions o;
    o.max_iterations = 2;
    const auto fit = rths::ident::FitSpencer({rec}, o);
    CHECK_FALSE(fit.status.converged);
    CHECK_FALSE(fit.status.Ok());
    CHECK(fit.status.iterations <= 2 + 10 * 8);
    CHECK(fit.status.Summary().find("not converged") != std::string::npos);
    const std::string toml = rths::ident::SpencerModelToml(fit, "test");
    CHECK(toml.find("# FIT FAILED") != std::string::npos);
    CHECK(toml.find("status = \"failed\"\nconverged = false") != std::string::npos);
    const auto dir = rths_test::TempDir("fit_status_early");
    const auto path = (dir / "model.toml").string();
    { std::ofstream(path) << toml; }
    CHECK(rths::scenario::LoadScenario(path).plant.current_driver.kind == m::CurrentFilter::kFirstOrder);
  }
  SUBCASE("a damper stiffer than the range allows: k0 on its upper bound, the fit failed") {
    // k0 = 1000 kN/mm, ten times the top of its range (1e2): the fit stops there.
    const auto stiff = RigModeRecord(150.0, dt, 10.0, 12.0, 6.0, 21, "stiff", 0.001, 0.02, 1000.0);
    const auto fit = rths::ident::FitSpencer({stiff}, {});
    CAPTURE(fit.Report());
    CHECK(fit.params.k0 == doctest::Approx(1e2).epsilon(1e-5));
    CHECK_FALSE(fit.status.Ok());
    const auto at_bound = fit.status.Names(rths::ident::ParameterState::kAtBound);
    CHECK(std::find(at_bound.begin(), at_bound.end(), "k0") != at_bound.end());
    CHECK(rths::ident::SpencerModelToml(fit, "t").find("at_bound = [") != std::string::npos);
  }
  SUBCASE("the CLI: exit 3 for a failed fit, 0 with --accept-unconverged; the model is written both times") {
    const auto fast = RigModeRecord(150.0, dt, 10.0, 12.0, 6.0, 21, "stiff", 0.001, 0.02, 1000.0);
    const auto dir = rths_test::TempDir("fit_status_cli");
    const auto csv = (dir / "fast.csv").string(), model = (dir / "model.toml").string(),
               log = (dir / "out.txt").string();
    rths::io::WriteRigRecord(fast, csv);
    const auto cmd = fmt::format("{}/rths-identify --damper {} --out {} > {} 2>&1", RTHS_BIN_DIR, csv, model, log);
    const int status = std::system(cmd.c_str());
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == rths::ident::kExitFitFailed);
    CHECK(rths_test::Slurp(log).find("fit status: FAILED") != std::string::npos);
    CHECK(rths_test::Slurp(model).find("# FIT FAILED") != std::string::npos);
    // What to try (ident/fit_advice.h): the parameter, the records that would determine it, --hold, accepting.
    const std::string said = rths_test::Slurp(log);
    CAPTURE(said);
    CHECK(said.find("what to try") != std::string::npos);
    CHECK(said.find("k0 = 100 on its upper bound") != std::string::npos);
    CHECK(said.find("stiffness at large velocities") != std::string::npos);
    CHECK(said.find("--hold k0=VALUE") != std::string::npos);
    CHECK(said.find("--accept-unconverged exits 0") != std::string::npos);
    // A malformed --hold is bad input (exit 2), named; one --hold takes one value, not the record after it.
    const int bad = std::system(
        fmt::format("{}/rths-identify --damper --hold k0 {} > {} 2>&1", RTHS_BIN_DIR, csv, log).c_str());
    CHECK(WEXITSTATUS(bad) == 2);
    CHECK(rths_test::Slurp(log).find("--hold: \"k0\": expected NAME=VALUE") != std::string::npos);
    std::filesystem::remove(model);
    const int accepted = std::system(
        fmt::format("{}/rths-identify --damper {} --out {} --accept-unconverged > {} 2>&1", RTHS_BIN_DIR, csv, model, log)
            .c_str());
    CHECK(WEXITSTATUS(accepted) == 0);
    CHECK(rths_test::Slurp(model).find("status = \"failed\"") != std::string::npos);
  }
}

TEST_CASE("fit status: what the records cannot determine is held, a flat law's rate is irrelevant") {
  // Two records at constant currents 0 and 1 A (UTFSM's design): eta never shows, and two levels
  // fix each law at those levels only.
  const double dt = 0.005;
  std::vector<rths::io::RigRecord> recs;
  for (double current : {0.0, 1.0}) {
    auto r = rths::io::ReadUtfsmDamper(fmt::format("{}/data/utfsm/mr_damper/25mm0x5Hz{}A.txt", RTHS_SOURCE_DIR,
                                                   current == 0.0 ? "0" : "1"));
    CHECK(r.dt_s == doctest::Approx(dt));
    recs.push_back(std::move(r));
  }
  const auto fit = rths::ident::FitSpencer(recs, {});
  CAPTURE(fit.Report());
  CHECK(fit.status.converged);
  CHECK(fit.status.Ok());
  const auto held = fit.status.Names(rths::ident::ParameterState::kHeld);
  CHECK(held == std::vector<std::string>{"alpha_c", "c0_c", "c1_c", "beta_c", "gamma_c", "eta_1_s"});
  CHECK(fit.params.alpha_c == doctest::Approx(3.0));  // 3 / (1 A - 0 A)
  CHECK(fit.driver.eta_1_s == doctest::Approx(100.0));
  // Nothing ran to a bound of its range (before: alpha_c = 1000 in a two-current fit).
  CHECK(fit.status.Names(rths::ident::ParameterState::kAtBound).empty());
  CHECK(fit.Report().find("held, not fitted") != std::string::npos);
}

TEST_CASE("negative commands: a DAQ's small negative samples are taken as 0 with a warning; a bipolar one is refused") {
  const double dt = 0.0005;
  auto rec = RigModeRecord(150.0, dt, 10.0, 12.0, 6.0, 31, "negative");
  rec.v_V = rec.i_A;  // drive the voltage input with the same command
  rec.i_A.clear();
  // As the prototype damper's white-noise test: 0.15 % of the samples negative, down to -0.43 V
  // of a command that reaches about 2.4 V (its anti-alias filter rings at the steps).
  std::size_t set = 0;
  for (std::size_t k = 100; k < rec.size() && set < rec.size() * 15 / 10000; k += 600, ++set)
    rec.v_V[k] = -0.43 * static_cast<double>(set % 3 + 1) / 3.0;
  const auto c = rths::ident::CommandForModel(rec, true);
  CHECK(c.negatives == set);
  CHECK(c.worst == doctest::Approx(-0.43));
  CHECK(*std::min_element(c.v.begin(), c.v.end()) == 0.0);
  CHECK(c.warning.find(fmt::format("{} of {} samples of v_V", set, rec.size())) != std::string::npos);
  CHECK(c.warning.find("-0.43 V") != std::string::npos);
  CHECK(c.warning.find("taken as 0 V") != std::string::npos);
  rths::ident::DamperFitOptions three;
  three.max_iterations = 3;
  const auto fit = rths::ident::FitSpencer({rec}, three);
  REQUIRE(fit.warnings.size() == 1);
  CHECK(fit.warnings[0] == c.warning);
  CHECK(std::isfinite(rths::ident::ScoreSpencer(fit.params, fit.driver, fit.filter, rec, true).nrmse_f_pct));
  // A bipolar command (5 % of the samples negative) is refused, naming the rule.
  for (std::size_t k = 0; k < rec.size(); k += 20) rec.v_V[k] = -0.2;
  try {
    (void)rths::ident::CommandForModel(rec, true);
    FAIL("a bipolar command was accepted");
  } catch (const rths::Error& e) {
    const std::string what = e.what();
    CHECK(what.find("negative") != std::string::npos);
    CHECK(what.find("at most 1 %") != std::string::npos);
  }
}

namespace {

/// A parameter's status as a fit would leave it (fit_status.h).
rths::ident::ParameterStatus At(const std::string& name, double value, double lo, double hi) {
  return rths::ident::StatusOf(name, value, lo, hi, false);
}

}  // namespace

TEST_CASE("fit advice: each failed parameter maps to what would determine it and how to hold it") {
  using rths::ident::FitAdvice;
  rths::ident::AdviceContext three;  // sinusoids at 0, 0.5 and 1 A, the fit with any input
  three.any_input = true;
  three.input_min = 0.0;
  three.input_max = 1.0;
  three.levels = {0.0, 0.5, 1.0};
  rths::ident::FitStatus st;
  st.converged = true;
  st.iterations = 40;
  st.parameters = {At("alpha_c", 1000.0, 1e-4, 1e3), At("c0_b", 0.01, 1e-7, 1e4), At("c0_c", 2.0, 1e-4, 1e3)};
  REQUIRE(st.parameters[0].state == rths::ident::ParameterState::kAtBound);
  auto advice = FitAdvice(st, three);
  CAPTURE(advice);
  REQUIRE(advice.size() == 2);  // alpha_c on its bound, and --accept-unconverged
  // A rate on its upper bound: the law's change lies below the second level; records between 0 and
  // 0.5 A would determine it, or hold it at 3 / 0.5 A (95 % of the change by 0.5 A).
  CHECK(advice[0].find("alpha_c = 1000 1/A on its upper bound") != std::string::npos);
  CHECK(advice[0].find("between 0 and 0.5 A") != std::string::npos);
  CHECK(advice[0].find("--hold alpha_c=6 ") != std::string::npos);
  CHECK(advice[1].find("--accept-unconverged") != std::string::npos);

  // A rate on its lower bound: the law is linear, its saturated end beyond the records.
  st.parameters[0] = At("alpha_c", 1e-4, 1e-4, 1e3);
  advice = FitAdvice(st, three);
  CHECK(advice[0].find("higher inputs, toward the damper's saturation") != std::string::npos);
  CHECK(advice[0].find("--hold alpha_c=3 ") != std::string::npos);

  // Law ends and coefficients: the records that show them (Spencer et al. 1997's roles).
  st.parameters[0] = At("c0_b", 1e4, 1e-7, 1e4);
  CHECK(FitAdvice(st, three)[0].find("higher velocities") != std::string::npos);
  CHECK(FitAdvice(st, three)[0].find("at the highest input (1 A)") != std::string::npos);
  CHECK(FitAdvice(st, three)[0].find("--hold c0_b=VALUE (plausible: 0.0001 to 3.2 kN s/mm)") != std::string::npos);
  st.parameters[0] = At("c1_a", 1e4, 1e-7, 1e4);
  CHECK(FitAdvice(st, three)[0].find("low velocities") != std::string::npos);
  CHECK(FitAdvice(st, three)[0].find("at the lowest input (0 A)") != std::string::npos);
  st.parameters[0] = At("eta_1_s", 1e5, 1.0, 1e5);
  CHECK(FitAdvice(st, three)[0].find("command steps or pulses") != std::string::npos);
  CHECK(FitAdvice(st, three)[0].find("--filter none") != std::string::npos);
  rths::ident::AdviceContext one;  // the fit at one current
  one.current_A = 0.5;
  st.parameters = {At("gamma", 1e4, 1e-9, 1e4)};
  CHECK(FitAdvice(st, one)[0].find("several amplitudes") != std::string::npos);
  CHECK(FitAdvice(st, one)[0].find("at 0.5 A") != std::string::npos);

  // Not converged: says so, and what to hold.
  st.parameters = {At("gamma", 0.01, 1e-9, 1e4)};
  st.converged = false;
  advice = FitAdvice(st, one);
  REQUIRE(advice.size() == 2);
  CHECK(advice[0].find("not converged in 40 iterations") != std::string::npos);
  CHECK(advice[0].find("--hold") != std::string::npos);
  // A fit that is ok and plausible has none.
  st.converged = true;
  CHECK(FitAdvice(st, one).empty());
}

TEST_CASE("plausible ranges: Table 3 is plausible, c0_b = 71.5 kN s/mm is flagged, alpha's range scales with A") {
  using rths::ident::CheckPlausible;
  const auto t = m::MrDamperParams::Table3();
  const std::vector<std::pair<std::string, double>> table3 = {
      {"alpha_a", t.alpha_a}, {"alpha_b", t.alpha_b}, {"alpha_c", t.alpha_c}, {"c0_a", t.c0_a},
      {"c0_b", t.c0_b},       {"c0_c", t.c0_c},       {"c1_a", t.c1_a},       {"c1_b", t.c1_b},
      {"c1_c", t.c1_c},       {"beta_a", t.beta_a},   {"beta_b", t.beta_b},   {"beta_c", t.beta_c},
      {"gamma_a", t.gamma_a}, {"gamma_b", t.gamma_b}, {"gamma_c", t.gamma_c}, {"k0", t.k0},
      {"k1", t.k1},           {"eta_1_s", 190.0}};
  CHECK(CheckPlausible(table3, 300.0, false).empty());
  const auto flagged = CheckPlausible({{"c0_a", 0.01}, {"c0_b", 71.5}, {"x0", 1e6}}, 300.0, false);
  REQUIRE(flagged.size() == 1);
  CHECK(flagged[0].Warning() ==
        "c0_b = 71.5 kN s/mm is outside the plausible range 0.0001..3.2 kN s/mm (docs/identification.md "
        "\"Plausible ranges\")");
  // alpha z is invariant under z -> z / s, A -> A / s, alpha -> s alpha: at A = 30, 10 x the range.
  CHECK(CheckPlausible({{"alpha", 20.0}}, 300.0, false).size() == 1);
  CHECK(CheckPlausible({{"alpha", 20.0}}, 30.0, false).empty());
  // A rate per V has no published range; per A it has.
  CHECK(CheckPlausible({{"alpha_c", 500.0}}, 300.0, true).empty());
  CHECK(CheckPlausible({{"alpha_c", 500.0}}, 300.0, false).size() == 1);
  // The status records it: a warning line, [fit] implausible, the figure's mark; the fit stays ok.
  rths::ident::FitStatus st;
  st.converged = true;
  st.parameters = {At("c0_b", 71.5, 1e-7, 1e4)};
  st.implausible = CheckPlausible(rths::ident::FittedValues(st), 300.0, false);
  CHECK(st.Ok());
  CHECK(st.TomlTable().find("implausible = [\"c0_b\"]") != std::string::npos);
  CHECK(st.Comment().find("#   warning: c0_b = 71.5 kN s/mm is outside") != std::string::npos);
  CHECK(st.Mark() == "implausible: c0_b");
  st.parameters.push_back(At("alpha_c", 1000.0, 1e-4, 1e3));
  CHECK(st.Mark() == "FIT FAILED: alpha_c on its bound; implausible: c0_b");
  // A rate whose law is flat (both ends at zero) changes nothing: not judged.
  rths::ident::FitStatus flat;
  flat.converged = true;
  flat.parameters = {At("beta_a", 1e-9, 1e-9, 1e4), At("beta_b", 1e-9, 1e-9, 1e4), At("beta_c", 328.7, 1e-4, 1e3)};
  flat.parameters[0].state = flat.parameters[1].state = rths::ident::ParameterState::kAtZero;
  CHECK(rths::ident::FittedValues(flat).empty());
  flat.parameters[1] = At("beta_b", 0.01, 1e-9, 1e4);
  CHECK(CheckPlausible(rths::ident::FittedValues(flat), 300.0, false).size() == 1);  // beta_c = 328.7 1/A
  // The mark is one line of a figure's title: two names at most, then how many more.
  st.implausible = CheckPlausible({{"c0_b", 71.5}, {"c0_c", 1e-3}, {"beta_c", 300.0}}, 300.0, false);
  CHECK(st.Mark() == "FIT FAILED: alpha_c on its bound; implausible: c0_b, c0_c +1");
  rths::ident::AdviceContext c;
  c.any_input = true;
  c.input_max = 1.0;
  c.levels = {0.0, 0.5, 1.0};
  const auto advice = rths::ident::FitAdvice(st, c);
  CHECK(std::any_of(advice.begin(), advice.end(),
                    [](const std::string& a) { return a.rfind("c0_b: c0_b is the viscous damping", 0) == 0; }));
  // An implausible rate gets a value to hold it at: too slow (c0_c = 0.001, a linear law) saturates
  // by the highest input, 3 / 1 A; too fast (beta_c = 300) by the second level, 3 / 0.5 A.
  auto line = [&](const std::string& name) {
    for (const auto& a : advice)
      if (a.rfind(name + ": ", 0) == 0) return a;
    return std::string();
  };
  CHECK(line("c0_c").find("--hold c0_c=3 (95 % of the change by 1 A) (plausible: 0.1 to 52 1/A)") != std::string::npos);
  CHECK(line("beta_c").find("--hold beta_c=6 (95 % of the change by 0.5 A)") != std::string::npos);
}

TEST_CASE("plausible ranges: docs/identification.md's table is the code's") {
  // Every row "| `name` | unit | lo .. hi | ..." of the table under "### Plausible ranges".
  const std::string doc = rths_test::Slurp(RTHS_SOURCE_DIR "/docs/identification.md");
  const auto at = doc.find("### Plausible ranges");
  REQUIRE(at != std::string::npos);
  std::istringstream in(doc.substr(at));
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.rfind("| `", 0) != 0) continue;
    std::vector<std::string> cells;
    std::istringstream row(line.substr(1));
    for (std::string c; std::getline(row, c, '|');) cells.push_back(c.substr(c.find_first_not_of(' ')));
    REQUIRE(cells.size() >= 3);
    const std::string name = cells[0].substr(1, cells[0].find('`', 1) - 1);
    CAPTURE(name);
    const auto range = rths::ident::PlausibleRangeOf(name, 300.0, false);
    REQUIRE(range.has_value());
    CHECK(cells[1].rfind(range->unit, 0) == 0);
    CHECK(cells[2].rfind(fmt::format("{:g} .. {:g}", range->lo, range->hi), 0) == 0);
    ++rows;
  }
  CHECK(rows == 9);  // alpha, c0, c1, k0, k1, beta, gamma, the rates, eta
}

TEST_CASE("--hold: a parameter held at a value is not fitted; a name the fit lacks is refused, naming those it has") {
  const auto rec = RigModeRecord(150.0, 0.0005, 10.0, 12.0, 6.0, 21, "hold");
  rths::ident::DamperFitOptions o;
  o.max_iterations = 2;
  o.hold = {{"alpha_c", 6.0}, {"eta_1_s", 120.0}};
  const auto fit = rths::ident::FitSpencer({rec}, o);
  CHECK(fit.params.alpha_c == doctest::Approx(6.0).epsilon(1e-12));
  CHECK(fit.driver.eta_1_s == doctest::Approx(120.0).epsilon(1e-12));
  const auto held = fit.status.Names(rths::ident::ParameterState::kHeld);
  CHECK(held == std::vector<std::string>{"alpha_c", "eta_1_s"});
  CHECK(fit.Report().find("held, not fitted: held at 6 by --hold") != std::string::npos);
  o.hold = {{"alpha", 0.1}};  // a name of the fit at one current
  try {
    (void)rths::ident::FitSpencer({rec}, o);
    FAIL("an unknown parameter was held");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("not a parameter of this fit; it has alpha_a, alpha_b, alpha_c") !=
          std::string::npos);
  }
  o.hold = {{"alpha_c", 1e6}};
  try {
    (void)rths::ident::FitSpencer({rec}, o);
    FAIL("a value outside the range was held");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("alpha_c = 1e+06: outside the fit's range for it, 0.0001 to 1000") !=
          std::string::npos);
  }
  CHECK(rths::ident::ParseHold("c0_b=0.25") == std::pair<std::string, double>{"c0_b", 0.25});
  CHECK_THROWS_AS(rths::ident::ParseHold("c0_b"), rths::Error);
  CHECK_THROWS_AS(rths::ident::ParseHold("c0_b=-1"), rths::Error);
  CHECK_THROWS_AS(rths::ident::ParseHold("=1"), rths::Error);
}
