// Identification (ident/fit.h, ident/identify.h): exact recovery from exact frequency responses,
// E1 on the linear plants (docs/experiments.md), and the real UTFSM chirp record.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "core/error.h"
#include "ident/actuator_fit.h"
#include "ident/fit.h"
#include "ident/identify.h"
#include "io/utfsm.h"
#include "models/servo_linear.h"
#include "scenario/scenario.h"
#include "signal/blwn.h"
#include "test_support.h"

namespace {

using cd = std::complex<double>;
using rths::ident::FitOptions;
using rths::ident::FitPoleModel;
using rths::ident::PoleModel;
using rths::models::ServoModel3;

const ServoModel3 kEq28{1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};
const ServoModel3 kEq29{1.613e7, 134.2, 324.6, 1.211e5, "2.5A"};
const ServoModel3 kEq30{1.600e7, 151.7, 250.4, 1.061e5, "avg"};

double Rel(double got, double want) { return got / want - 1.0; }

struct Frf {
  std::vector<double> f, coh;
  std::vector<cd> h;
};
template <class G>
Frf MakeFrf(G g, double df, double fmax) {
  Frf r;
  for (double f = 0.0; f <= fmax + 1e-9; f += df) {
    r.f.push_back(f);
    r.h.push_back(g(f));
    r.coh.push_back(1.0);
  }
  return r;
}

/// E1: BLWN 0-50 Hz, RMS 0.254 mm, 60 s at 2 kHz through the ZOH LinearServo; y_k from u_0..u_{k-1}.
struct E1Record {
  std::vector<double> u, y;
};
E1Record SimulateE1(const ServoModel3& m, double dt = 0.0005) {
  const std::size_t n = static_cast<std::size_t>(60.0 / dt);
  E1Record r;
  r.u = rths::signal::Blwn(50.0, 0.254, dt, n, 1, 2.0);
  r.y.resize(n);
  const auto servo = rths::models::LinearServo::Make(m, dt);
  rths::models::LinearServoState s;
  for (std::size_t k = 0; k < n; ++k) {
    r.y[k] = rths::models::Output(servo, s);
    rths::models::Step(servo, &s, r.u[k]);
  }
  return r;
}

}  // namespace

TEST_CASE("the fit recovers K, p, b, c of Eqs. 28-30 from their exact frequency response to 1e-6") {
  for (const auto& m : {kEq28, kEq29, kEq30}) {
    const auto pm = PoleModel::FromServoModel3(m);
    const auto frf = MakeFrf([&](double f) { return pm.Response(f); }, 0.25, 50.0);
    for (auto w : {rths::ident::Weighting::kInverseVariance, rths::ident::Weighting::kCoherence,
                   rths::ident::Weighting::kUniform}) {
      FitOptions o;
      o.weighting = w;
      const auto fit = FitPoleModel(frf.f, frf.h, frf.coh, o);
      const auto s = fit.model.ToServoModel3();
      CAPTURE(m.name);
      CHECK(std::abs(Rel(s.K, m.K)) < 1e-6);
      CHECK(std::abs(Rel(s.p, m.p)) < 1e-6);
      CHECK(std::abs(Rel(s.b, m.b)) < 1e-6);
      CHECK(std::abs(Rel(s.c, m.c)) < 1e-6);
      CHECK(fit.rms_rel_error < 1e-8);
      CHECK(fit.converged);
    }
    // DC gain and DC lag d1/d0 against docs/models.md section 1.
    FitOptions o;
    const auto fit = FitPoleModel(frf.f, frf.h, frf.coh, o);
    const double d0 = m.p * m.c, d1 = m.p * m.b + m.c;
    CHECK(fit.model.DcGain() == doctest::Approx(m.K / d0).epsilon(1e-8));
    CHECK(fit.model.DcLagS() == doctest::Approx(d1 / d0).epsilon(1e-8));
  }
  CHECK(PoleModel::FromServoModel3(kEq28).DcLagS() * 1e3 == doctest::Approx(7.85).epsilon(1e-3));
  CHECK(PoleModel::FromServoModel3(kEq29).DcLagS() * 1e3 == doctest::Approx(10.13).epsilon(1e-3));
}

TEST_CASE("other orders: N = 1, 2, 4, 5 recovered from exact responses; poles always stable") {
  std::vector<PoleModel> models(4);
  models[0].K = 150.0, models[0].p = 150.0;
  models[1].K = 9e4, models[1].b = {200.0}, models[1].c = {9e4};
  models[2].K = 1e12, models[2].b = {200.0, 900.0}, models[2].c = {9e4, 1.6e6};
  models[3].K = 3e14, models[3].p = 180.0, models[3].b = {200.0, 900.0}, models[3].c = {9e4, 1.6e6};
  for (const auto& m : models) {
    const auto frf = MakeFrf([&](double f) { return m.Response(f); }, 0.25, 60.0);
    FitOptions o;
    o.poles = m.Order();
    o.band_hi_hz = 60.0;
    const auto fit = FitPoleModel(frf.f, frf.h, frf.coh, o);
    CAPTURE(m.Order());
    CHECK(fit.model.Order() == m.Order());
    CHECK(fit.rms_rel_error < 1e-6);
    CHECK(std::abs(Rel(fit.model.DcGain(), m.DcGain())) < 1e-6);
  }
  // Data from an unstable system: the fitted poles are still in the left half plane.
  PoleModel unstable;
  unstable.K = 100.0;
  const auto frf = MakeFrf([&](double f) { return 100.0 / cd(-100.0, 2.0 * M_PI * f); }, 0.5, 40.0);
  FitOptions o;
  o.poles = 1;
  const auto fit = FitPoleModel(frf.f, frf.h, frf.coh, o);
  for (const auto& p : fit.model.Poles()) CHECK(p.real() < 0.0);
}

TEST_CASE("the ZOH discretisation of a PoleModel equals LinearServo's, and SimulateZoh its steps") {
  const double dt = 0.0005;
  const auto servo = rths::models::LinearServo::Make(kEq29, dt);
  const auto z = rths::ident::Discretise(PoleModel::FromServoModel3(kEq29), dt);
  for (double f : {0.5, 5.0, 20.0, 40.0, 300.0})
    CHECK(std::abs(rths::ident::ZohResponse(z, f) - rths::models::FrequencyResponse(servo, f, true)) < 1e-10);
  const auto u = rths::signal::Blwn(50.0, 0.254, dt, 4000, 3, 0.5);
  const auto y = rths::ident::SimulateZoh(z, u);
  rths::models::LinearServoState s;
  double worst = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    worst = std::max(worst, std::abs(y[k] - rths::models::Output(servo, s)));
    rths::models::Step(servo, &s, u[k]);
  }
  CHECK(y[0] == 0.0);
  CHECK(worst < 1e-12);
}

TEST_CASE("exact ZOH response: the continuous fit absorbs the hold's half sample; the ZOH-consistent fit is exact") {
  const double dt = 0.0005;
  for (const auto& m : {kEq28, kEq29}) {
    const auto servo = rths::models::LinearServo::Make(m, dt);
    const auto frf = MakeFrf([&](double f) { return rths::models::FrequencyResponse(servo, f, true); }, 0.25, 50.0);
    FitOptions o;
    const auto cont = FitPoleModel(frf.f, frf.h, frf.coh, o);
    const auto fc = cont.model.ToServoModel3();
    MESSAGE(fmt::format("{} exact ZOH FRF, continuous 3-pole fit 0.5-40 Hz: K {:+.2f} %, p {:+.2f} %, b {:+.2f} %, "
                        "c {:+.2f} %; fit error {:.3f} %; DC lag {:.3f} ms (Eq.: {:.3f} ms)",
                        m.name, 100 * Rel(fc.K, m.K), 100 * Rel(fc.p, m.p), 100 * Rel(fc.b, m.b), 100 * Rel(fc.c, m.c),
                        100 * cont.rms_rel_error, 1e3 * cont.model.DcLagS(),
                        1e3 * PoleModel::FromServoModel3(m).DcLagS()));
    // The half-sample lag of the hold goes into the poles: DC lag up by about dt/2.
    CHECK((cont.model.DcLagS() - PoleModel::FromServoModel3(m).DcLagS()) == doctest::Approx(dt / 2).epsilon(0.2));
    CHECK(cont.rms_rel_error < 0.01);
    o.zoh_dt_s = dt;
    const auto fz = FitPoleModel(frf.f, frf.h, frf.coh, o).model.ToServoModel3();
    CHECK(std::abs(Rel(fz.K, m.K)) < 1e-6);
    CHECK(std::abs(Rel(fz.p, m.p)) < 1e-6);
    CHECK(std::abs(Rel(fz.b, m.b)) < 1e-6);
    CHECK(std::abs(Rel(fz.c, m.c)) < 1e-6);
  }
}

TEST_CASE("E1 on the linear plants: BLWN 0-50 Hz, 0.254 mm RMS, 60 s through the ZOH servo at 2 kHz") {
  const double dt = 0.0005;
  for (const auto& m : {kEq28, kEq29}) {
    const auto rec = SimulateE1(m, dt);
    for (double hi : {40.0, 50.0}) {
      rths::ident::IdentifyOptions o;
      o.fit.band_hi_hz = hi;
      const auto rc = rths::ident::Identify(rec.u, rec.y, dt, o);
      o.fit.zoh_dt_s = dt;
      const auto rz = rths::ident::Identify(rec.u, rec.y, dt, o);
      const auto c = rc.fit.model.ToServoModel3(), z = rz.fit.model.ToServoModel3();
      MESSAGE(fmt::format("E1 {} 0.5-{} Hz, continuous fit (Eq. 15, no delay): K {:+.2f} %, p {:+.2f} %, b {:+.2f} %, "
                          "c {:+.2f} %; fit error {:.3f} %; DC gain {:.4f}, DC lag {:.3f} ms; time domain {:.3f} % "
                          "(identity {:.1f} %)",
                          m.name, hi, 100 * Rel(c.K, m.K), 100 * Rel(c.p, m.p), 100 * Rel(c.b, m.b),
                          100 * Rel(c.c, m.c), 100 * rc.fit.rms_rel_error, rc.fit.model.DcGain(),
                          1e3 * rc.fit.model.DcLagS(), rc.prediction.model_error_pct,
                          rc.prediction.identity_error_pct));
      MESSAGE(fmt::format("E1 {} 0.5-{} Hz, ZOH-consistent fit: K {:+.3f} %, p {:+.3f} %, b {:+.3f} %, c {:+.3f} %; "
                          "fit error {:.3f} %; time domain {:.4f} %",
                          m.name, hi, 100 * Rel(z.K, m.K), 100 * Rel(z.p, m.p), 100 * Rel(z.b, m.b),
                          100 * Rel(z.c, m.c), 100 * rz.fit.rms_rel_error, rz.prediction.model_error_pct));
      CHECK(rc.frf.segments >= 8);
      // E1's criterion (3 %) holds for the model whose ZOH simulation reproduces the record.
      CHECK(std::abs(Rel(z.K, m.K)) < 0.03);
      CHECK(std::abs(Rel(z.p, m.p)) < 0.03);
      CHECK(std::abs(Rel(z.b, m.b)) < 0.03);
      CHECK(std::abs(Rel(z.c, m.c)) < 0.03);
      CHECK(rz.prediction.model_error_pct < 0.1);
      // The delay-free continuous fit cannot reach 3 % on ZOH data (the hold's 0.25 ms goes into
      // the poles, K follows p c at a DC gain of 1): measured 3-10.5 %, kept from growing here.
      CHECK(std::abs(Rel(c.K, m.K)) < 0.12);
      CHECK(std::abs(Rel(c.p, m.p)) < 0.08);
      CHECK(std::abs(Rel(c.b, m.b)) < 0.08);
      CHECK(std::abs(Rel(c.c, m.c)) < 0.10);
      CHECK(rc.fit.rms_rel_error < 0.01);
      CHECK(rc.fit.model.DcGain() == doctest::Approx(m.K / (m.p * m.c)).epsilon(0.015));
      CHECK((rc.fit.model.DcLagS() - m.b / m.c - 1.0 / m.p) == doctest::Approx(dt / 2).epsilon(0.25));

      // The printed fragment is a valid scenario part: run.dt_s = the record's step (its [run]
      // table takes more keys), plant.actuator = the ZOH-consistent fit, controller.model = the
      // continuous fit.
      const auto dir = rths_test::TempDir("identify_fragment");
      std::string fragment = rths::ident::ScenarioFragment(rc, rz, "E1");
      const auto run_table = fragment.find("[run]\n");
      REQUIRE(run_table != std::string::npos);
      fragment.insert(run_table + 6, "duration_s = 0.5\n");
      const auto sc = rths::scenario::LoadScenario(rths_test::WriteScenario(dir, fragment).string());
      CHECK(sc.run.dt_s == rz.dt_s);
      CHECK(sc.plant.actuator.K == doctest::Approx(z.K).epsilon(1e-9));
      CHECK(sc.plant.actuator.c == doctest::Approx(z.c).epsilon(1e-9));
      CHECK(sc.controller.model.p == doctest::Approx(c.p).epsilon(1e-9));
      CHECK(sc.controller.model.b == doctest::Approx(c.b).epsilon(1e-9));
    }
  }
}

TEST_CASE("FitActuator: both fits of one record, their report, model file and Bode figure") {
  const double dt = 0.0005;
  const auto rec = SimulateE1(kEq28, dt);
  rths::ident::IdentifyOptions o;
  o.fit.zoh_dt_s = 0.123;  // not used: the continuous fit has 0, the ZOH-consistent one dt
  const auto fit = rths::ident::FitActuator(rec.u, rec.y, dt, o);
  CHECK(fit.continuous.options.fit.zoh_dt_s == 0.0);
  CHECK(fit.zoh.options.fit.zoh_dt_s == dt);
  const auto z = fit.zoh.fit.model.ToServoModel3();
  CHECK(std::abs(Rel(z.K, kEq28.K)) < 0.03);
  CHECK(std::abs(Rel(z.c, kEq28.c)) < 0.03);
  // The report: the continuous fit's, then the ZOH-consistent fit's with its time-domain error.
  const std::string report = fit.Report();
  CHECK(report.rfind(fit.continuous.Report(), 0) == 0);
  CHECK(report.find("ZOH-consistent fit (the continuous model whose zero-order-hold discretisation at dt = 0.0005 s") !=
        std::string::npos);
  CHECK(report.find(fit.zoh.fit.Report()) != std::string::npos);
  CHECK(report.find(fmt::format("time domain: Eq. 31 error of the predicted y {:.3f} %", fit.zoh.prediction.model_error_pct)) !=
        std::string::npos);
  CHECK(fit.ModelToml("E1") == rths::ident::ScenarioFragment(fit.continuous, fit.zoh, "E1"));

  const auto fig = fit.Bode("G_yu test");
  CHECK(fig.title == "G_yu test");
  REQUIRE(fig.panels.size() == 4);
  const auto& mag = fig.panels[0];
  const auto& phase = fig.panels[1];
  REQUIRE(mag.series.size() == 3);
  REQUIRE(phase.series.size() == 3);
  CHECK(fig.panels[3].series.size() == 1);  // coherence: the measurement only
  // Models on 500 points up to 50 Hz (below the 1 kHz Nyquist frequency).
  const auto& cont = phase.series[1];
  REQUIRE(cont.x.size() == 500);
  CHECK(cont.x.back() == doctest::Approx(50.0));
  // The continuous model's phase, unwrapped: the sum of its factors' phases (no 2 pi jumps).
  const auto m = fit.continuous.fit.model.ToServoModel3();
  for (std::size_t i : {std::size_t{0}, std::size_t{249}, std::size_t{499}}) {
    const double w = 2.0 * std::numbers::pi * cont.x[i];
    const double want = -(std::atan2(w, m.p) + std::atan2(m.b * w, m.c - w * w)) * 180.0 / std::numbers::pi;
    CHECK(cont.y[i] == doctest::Approx(want).epsilon(1e-9));
    CHECK(mag.series[1].y[i] == doctest::Approx(std::abs(fit.continuous.fit.model.Response(cont.x[i]))).epsilon(1e-12));
    const double zoh_mag =
        std::abs(rths::ident::ZohResponse(rths::ident::Discretise(fit.zoh.fit.model, dt), cont.x[i]));
    CHECK(mag.series[2].y[i] == doctest::Approx(zoh_mag).epsilon(1e-12));
  }
  // The measurement: excited points of (0, 50] Hz only, the fitted band shaded.
  const auto& meas = mag.series[0];
  REQUIRE(!meas.x.empty());
  CHECK(meas.x.front() > 0.0);
  CHECK(meas.x.back() <= 50.0);
  REQUIRE(mag.shade_x.has_value());
  CHECK(mag.shade_x->first == fit.continuous.fitted_lo_hz);
  CHECK(mag.shade_x->second == fit.continuous.fitted_hi_hz);
  // The lag axis spans the models' lags with 30 % either side.
  const auto& lag = fig.panels[2];
  double lo = 1e300, hi = -1e300;
  for (std::size_t s = 1; s < 3; ++s)
    for (double l : lag.series[s].y) lo = std::min(lo, l), hi = std::max(hi, l);
  REQUIRE(lag.y_range.has_value());
  CHECK(lag.y_range->first == doctest::Approx(0.7 * lo));
  CHECK(lag.y_range->second == doctest::Approx(1.3 * hi));
}

TEST_CASE("chirp_0A (UTFSM rig): identify on the first half, predict the second half") {
  const auto rec = rths::io::ReadUtfsmActuator(RTHS_SOURCE_DIR "/data/utfsm/actuator/chirp_0A.txt");
  const std::size_t n = rec.size(), h = n / 2;
  const std::span<const double> u(rec.u_mm), y(rec.y_mm);
  rths::ident::IdentifyOptions o;  // the defaults of rths identify: 0.5-40 Hz, 3 poles
  const auto r = rths::ident::Identify(u.subspan(0, h), y.subspan(0, h), rec.dt_s, o);
  const auto test = rths::ident::PredictDisplacement(r.fit.model, rec.dt_s, u, y, h, n);
  o.fit.zoh_dt_s = rec.dt_s;
  const auto rz = rths::ident::Identify(u.subspan(0, h), y.subspan(0, h), rec.dt_s, o);
  const auto testz = rths::ident::PredictDisplacement(rz.fit.model, rec.dt_s, u, y, h, n);
  const auto& m = r.fit.model;
  MESSAGE(fmt::format("chirp_0A first half ({:.1f} s, fitted {:.2f}-{:.2f} Hz): G(s) = {:.6g} / ((s + {:.6g})(s^2 + "
                      "{:.6g} s + {:.6g})); fit error {:.2f} %; DC gain {:.4f}, DC lag {:.2f} ms",
                      h * rec.dt_s, r.fitted_lo_hz, r.fitted_hi_hz, m.K, m.p, m.b[0], m.c[0],
                      100 * r.fit.rms_rel_error, m.DcGain(), 1e3 * m.DcLagS()));
  MESSAGE(fmt::format("chirp_0A Eq. 31 error of the predicted y: first half {:.2f} %, second half {:.2f} % (identity "
                      "y = u: {:.2f} % / {:.2f} %); ZOH-consistent fit {:.2f} % / {:.2f} %",
                      r.prediction.model_error_pct, test.model_error_pct, r.prediction.identity_error_pct,
                      test.identity_error_pct, rz.prediction.model_error_pct, testz.model_error_pct));
  CHECK(r.fit.rms_rel_error < 0.05);
  CHECK(m.DcGain() == doctest::Approx(1.0).epsilon(0.05));
  CHECK(r.prediction.model_error_pct < 5.0);
  // Held-out half (higher frequencies than fitted): far better than no model at all.
  CHECK(test.model_error_pct < 25.0);
  CHECK(test.model_error_pct < 0.2 * test.identity_error_pct);
  CHECK(testz.model_error_pct < 0.2 * test.identity_error_pct);
}

TEST_CASE("fit and identify reject bad input") {
  const std::vector<double> f{1, 2, 3}, c{1, 1, 1};
  const std::vector<cd> h{1.0, 1.0, 1.0};
  FitOptions o;
  CHECK_THROWS_AS(FitPoleModel(f, h, c, o), rths::Error);  // too few points
  o.poles = 0;
  CHECK_THROWS_AS(FitPoleModel(f, h, c, o), rths::Error);
  o = FitOptions{};
  o.band_hi_hz = 0.1;
  std::string why;
  CHECK_FALSE(o.IsValid(&why));
  CHECK(why.find("band_hi_hz") != std::string::npos);
  CHECK_THROWS_AS(rths::ident::Identify(std::vector<double>(100), std::vector<double>(99), 0.001, {}), rths::Error);
  PoleModel two;
  two.K = 1, two.b = {1}, two.c = {1};
  CHECK_THROWS_AS(two.ToServoModel3(), rths::Error);
}
