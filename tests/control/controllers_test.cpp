// Tests for the tracking controllers of Table 1 (lib/control: baselines, inverse_lowpass, lqg,
// tracking_controller): design values of docs/models.md section 3, the discrete controllers against their
// continuous designs, E2 (docs/experiments.md) on a plant equal to the design model, the offline
// time-domain numbers of docs/models.md section 10, allocation-free steps, and refused designs.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "control/analysis.h"
#include "control/baselines.h"
#include "control/design.h"
#include "control/inverse_lowpass.h"
#include "control/lqg.h"
#include "control/tracking_controller.h"
#include "core/error.h"
#include "models/servo_linear.h"
#include "signal/blwn.h"
#include "signal/metrics.h"

#include <Eigen/Dense>

#include "alloc_counter.h"

namespace ctl = rths::control;
namespace sig = rths::signal;
namespace mdl = rths::models;
using rths::control::ControllerConfig;
using rths::models::ServoModel3;
using rths::models::ServoPreset;
using cd = std::complex<double>;
using std::numbers::pi;

namespace {

constexpr double kDt = 0.0005;  // 2 kHz

ControllerConfig Config(const std::string& kind, const char* model = "avg", double delay_ms = 9.0) {
  ControllerConfig c;
  // "unknown": a value no kind has (only a corrupted config can hold one).
  c.kind = kind == "unknown" ? static_cast<rths::control::ControllerKind>(42)
                             : rths::ParseName(rths::control::kControllerKindNames, kind, "kind");
  c.model = ServoPreset(model);
  c.delay_ms = delay_ms;
  return c;
}


}  // namespace

// ---------------------------------------------------------------------------------------------
// Design values (docs/models.md section 3)

TEST_CASE("poly3: Horiuchi coefficients for 8 / 9 / 10 ms at 2 kHz, sum 1, Nyquist gain") {
  struct Case { double ms; std::array<double, 4> c; double nyquist; };
  for (const Case& k : {Case{8, {969, -2736, 2584, -816}, 7100}, Case{9, {1330, -3780, 3591, -1140}, 9800},
                        Case{10, {1771, -5060, 4830, -1540}, 13200}}) {
    const ctl::Poly3Design d = ctl::MakePoly3(k.ms * 1e-3, kDt);
    for (int i = 0; i < 4; ++i) CHECK(d.c[i] == doctest::Approx(k.c[i]).epsilon(1e-12));
    CHECK(d.c[0] + d.c[1] + d.c[2] + d.c[3] == doctest::Approx(1.0).epsilon(1e-9));
    CHECK(d.nyquist_gain == doctest::Approx(k.nyquist).epsilon(0.01));  // "about" in the spec
  }
  // The cubic through four samples reproduces any cubic exactly, tau ahead.
  const ctl::Poly3Design d = ctl::MakePoly3(0.008, kDt);
  ctl::PolynomialExtrapolation p(d, kDt);
  const auto cubic = [](double t) { return 1.0 + 2.0 * t - 30.0 * t * t + 400.0 * t * t * t; };
  double u = 0.0;
  for (int k = 0; k < 10; ++k) u = p.Step({cubic(k * kDt)}, {}).u_mm;
  CHECK(u == doctest::Approx(cubic(9 * kDt + 0.008)).epsilon(1e-9));
}

TEST_CASE("lead: Tustin coefficients for tau = 8 ms, T_p = 0.5 ms") {
  const ctl::LeadDesign d = ctl::MakeLead(0.008, 0.0005, kDt);
  CHECK(d.tz_s == doctest::Approx(0.0085));
  CHECK(d.b0 == doctest::Approx(11.6667).epsilon(1e-5));
  CHECK(d.b1 == doctest::Approx(-11.0000).epsilon(1e-5));
  CHECK(d.a1 == doctest::Approx(-0.33333).epsilon(1e-5));
  CHECK((d.b0 + d.b1) / (1.0 + d.a1) == doctest::Approx(1.0));  // unit DC gain
}

TEST_CASE("ff_lp: third-order Butterworth inverse at 318 Hz: stable sections, DC gain 1/G(0), 1 ms group delay") {
  for (const char* m : {"0.0A", "2.5A", "avg"}) {
    const ServoModel3 model = ServoPreset(m);
    const ctl::InverseLowpassDesign d = ctl::MakeInverseLowpass(model, 3, 318.0, kDt, "controller.model");
    CHECK(d.sos.sections.size() == 2);
    CHECK(d.dc_group_delay_s == doctest::Approx(2.0 / (2.0 * pi * 318.0)).epsilon(1e-12));
    CHECK(d.dc_group_delay_s == doctest::Approx(1.0e-3).epsilon(0.001));
    const ctl::DiscreteSs s = ctl::FromSos(d.sos, kDt);
    CHECK(s.A.eigenvalues().cwiseAbs().maxCoeff() < 1.0);
    CHECK(std::abs(s.Response(0.0)) == doctest::Approx(model.p * model.c / model.K).epsilon(1e-12));
  }
  // Every order 3..8 designs a stable proper filter whose DC gain inverts the model.
  for (int n = 3; n <= 8; ++n) {
    const ctl::InverseLowpassDesign d = ctl::MakeInverseLowpass(ServoPreset("avg"), n, 200.0, kDt, "k");
    CHECK(d.sos.sections.size() == static_cast<std::size_t>((n + 1) / 2));
    CHECK(ctl::FromSos(d.sos, kDt).A.eigenvalues().cwiseAbs().maxCoeff() < 1.0);
    CHECK(std::abs(d.Analog(1e-6) - cd(1.0 / 0.99407, 0)) < 1e-4);
  }
}

// ---------------------------------------------------------------------------------------------
// Each discrete controller against its continuous design

TEST_CASE("frequency response: ff (Eq. 19 with Eqs. 20-22) against G^-1(j w), within the extrapolation error") {
  for (const char* m : {"0.0A", "2.5A", "avg"}) {
    const ServoModel3 model = ServoPreset(m);
    const ctl::FeedforwardCoefficients a = ctl::MakeFeedforwardCoefficients(model);
    const ctl::ControllerLti lti = ctl::MakeTrackingController(Config("ff", m), kDt)->Linearize(0.0);
    for (double f : {1.0, 5.0, 10.0, 20.0, 30.0}) {
      const double w = 2.0 * pi * f, x = w * kDt;
      const cd s(0.0, w);
      const cd ginv = (s + model.p) * (s * s + model.b * s + model.c) / model.K;
      // For r = e^{j w t}: the jerk of Eq. 22 is a difference of accelerations centred 1.5 steps
      // back, a relative error of 1.5 w dt to first order; Eqs. 20 and 21 err by O((w dt)^2).
      const double jerk = 1.5 * x * a.a3 * w * w * w;
      const double bound = 1.1 * (jerk + 1.2 * x * x * (a.a1 * w + a.a2 * w * w));
      CHECK(std::abs(lti.ff.Response(f) - ginv) < bound);
      CHECK(std::abs(lti.ff.Response(f) - ginv) > 0.5 * jerk);  // the jerk's lag dominates
    }
  }
}

TEST_CASE("frequency response: poly3 against the pure advance e^{j w tau}, within the cubic remainder") {
  for (double ms : {8.0, 9.0, 10.0}) {
    const ctl::ControllerLti lti = ctl::MakeTrackingController(Config("poly3", "avg", ms), kDt)->Linearize(0.0);
    const double a = ms * 1e-3 / kDt;
    for (double f : {1.0, 2.0, 5.0, 10.0}) {
      const double w = 2.0 * pi * f, x = w * kDt;
      // |r(t + tau) - p(t + tau)| <= max|r''''| / 4! prod_{i=0..3} (tau + i dt) = w^4 dt^4 a(a+1)(a+2)(a+3) / 24
      const double bound = std::pow(x, 4) * a * (a + 1) * (a + 2) * (a + 3) / 24.0;
      const cd err = lti.ff.Response(f) - std::polar(1.0, w * ms * 1e-3);
      CHECK(std::abs(err) <= 1.0001 * bound);
      CHECK(std::abs(err) >= 0.5 * bound);  // and the remainder is what it is
    }
  }
}

TEST_CASE("frequency response: lead and ff_lp are Tustin images of their continuous designs") {
  const auto warp = [](double f) { return std::tan(pi * f * kDt) / (pi * kDt); };  // (2/dt) tan(w dt/2) / 2 pi
  // lead: C(s) = (T_z s + 1) / (T_p s + 1)
  const ctl::LeadDesign ld = ctl::MakeLead(0.008, 0.0005, kDt);
  const ctl::ControllerLti lead = ctl::LeadCompensator(ld, kDt).Linearize(0.0);
  const auto lead_c = [&](double f) {
    const cd s(0.0, 2.0 * pi * f);
    return (ld.tz_s * s + 1.0) / (ld.tp_s * s + 1.0);
  };
  // ff_lp: LP(s) G^-1(s)
  const ctl::InverseLowpassDesign fd = ctl::MakeInverseLowpass(ServoPreset("0.0A"), 3, 318.0, kDt, "k");
  const ctl::ControllerLti fflp = ctl::InverseLowpass(fd).Linearize(0.0);
  for (double f : {0.5, 5.0, 20.0, 50.0, 200.0, 900.0}) {
    CHECK(std::abs(lead.ff.Response(f) / lead_c(warp(f)) - 1.0) < 1e-10);
    CHECK(std::abs(fflp.ff.Response(f) / fd.Analog(warp(f)) - 1.0) < 1e-9);
  }
  // Without prewarping, the two agree with the unwarped design at low frequency:
  // tan(w dt / 2) = (w dt / 2)(1 + (w dt)^2 / 12 + ...).
  for (double f : {1.0, 5.0, 10.0, 30.0}) {
    const double x = 2.0 * pi * f * kDt;
    CHECK(std::abs(lead.ff.Response(f) / lead_c(f) - 1.0) < x * x);
    CHECK(std::abs(fflp.ff.Response(f) / fd.Analog(f) - 1.0) < x * x);
  }
}

TEST_CASE("every controller's Step() is its Linearize() (and bumpless blends, never switches, its filters)") {
  const std::size_t n = 3000;
  const std::vector<double> r = sig::Blwn(40.0, 1.0, kDt, n, 3, 0.1), y = sig::Blwn(20.0, 1.0, kDt, n, 4, 0.1);
  for (const char* kind : {"none", "ff", "poly3", "lead", "ff_lp", "bumpless_lp", "ff_lqg"}) {
    CAPTURE(kind);
    ControllerConfig cfg = Config(kind, "avg", 8.0);
    cfg.half_step_ahead = std::string(kind) == "ff_lqg";
    auto c = ctl::MakeTrackingController(cfg, kDt);
    // Linear maps: u = F r + C_fb (y - r); bumpless: u = (1 - l_k) F_low r + l_k F_high r.
    const ctl::ControllerLti lo = c->Linearize(0.0), hi = c->Linearize(cfg.current_high_A);
    std::vector<double> e(n), i_A(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = y[k] - r[k], i_A[k] = 1.5 + 1.5 * std::sin(k * 0.01);  // 0..3 A
    const std::vector<double> u_lo = ctl::Simulate(lo.ff, r), u_hi = ctl::Simulate(hi.ff, r);
    const std::vector<double> u_fb = lo.has_feedback ? ctl::Simulate(lo.fb, e) : std::vector<double>(n, 0.0);
    ctl::ExtrapolationState past;
    double worst = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const ctl::Command u = c->Step(ctl::StepDerivatives(&past, r[k], kDt), {y[k], 0.0, i_A[k]});
      const double lambda = std::string(kind) == "bumpless_lp" ? std::min(i_A[k] / 2.5, 1.0) : 0.0;
      const double expect = (1.0 - lambda) * u_lo[k] + lambda * u_hi[k] + u_fb[k];
      worst = std::max(worst, std::abs(u.u_mm - expect) / (1.0 + std::abs(expect)));
      CHECK(u.u_mm == doctest::Approx(u.u_ff_mm + u.u_fb_mm));
    }
    CHECK(worst < 1e-9);
  }
}

// ---------------------------------------------------------------------------------------------
// E2 (docs/experiments.md): G_yr = C(z) G_d(z) on a plant equal to the design model, evaluated at
// z = e^{j w dt}; lag = -arg G_yr / w.

namespace {
struct E2 {
  ctl::ControllerLti c;
  ctl::DiscreteSs g;
  double Mag(double f) const { return std::abs(ctl::TrackingResponse(c, g, f)); }
  double Lag(double f) const { return ctl::TrackingLagS(c, g, f); }
};
E2 MakeE2(const ControllerConfig& cfg, const char* plant) {
  return {ctl::MakeTrackingController(cfg, kDt)->Linearize(0.0), ctl::ServoZoh(ServoPreset(plant), kDt)};
}
}  // namespace

TEST_CASE("E2: the proposed FF tracks within +/-10 % and +/-1 ms up to 30 Hz") {
  for (const char* m : {"0.0A", "2.5A", "avg"}) {
    const E2 e = MakeE2(Config("ff", m), m);
    std::printf("E2 FF %-4s f [Hz] |G_yr| lag [ms]:", m);
    double first_above_5 = 0.0;
    for (double f = 0.5; f <= 50.0; f += 0.5) {
      if (f <= 30.0) {
        CHECK(std::abs(e.Mag(f) - 1.0) <= 0.10);
        CHECK(std::abs(e.Lag(f)) <= 1e-3);
      }
      if (first_above_5 == 0.0 && e.Mag(f) > 1.05) first_above_5 = f;
      if (std::fmod(f, 10.0) == 0.0) std::printf("  %g %.3f %.3f", f, e.Mag(f), e.Lag(f) * 1e3);
    }
    std::printf("; > +5 %% from %g Hz\n", first_above_5);
    CHECK((first_above_5 == 0.0 || first_above_5 > 30.0));  // computed: only above about 37 Hz
  }
}

TEST_CASE("E2: FF + LP has a nearly constant lag of its low-pass delay plus half a sample (~1.25 ms)") {
  for (const char* m : {"0.0A", "2.5A"}) {
    ControllerConfig cfg = Config("ff_lp", m);
    const E2 e = MakeE2(cfg, m);
    const double expect = 2.0 / (2.0 * pi * cfg.lp_cutoff_hz) + kDt / 2.0;
    CHECK(expect == doctest::Approx(1.25e-3).epsilon(0.01));
    for (double f : {1.0, 5.0, 10.0, 20.0, 30.0, 40.0, 50.0}) {
      CHECK(e.Lag(f) == doctest::Approx(expect).epsilon(0.05));  // constant within 5 %
      CHECK(std::abs(e.Mag(f) - 1.0) < 0.05);
    }
    std::printf("E2 FF+LP %s: lag %.3f ms at 1 Hz, %.3f ms at 50 Hz (expected %.3f)\n", m, e.Lag(1.0) * 1e3,
                e.Lag(50.0) * 1e3, expect * 1e3);
  }
}

TEST_CASE("E2: 3rd Poly undershoots between 5 and 25 Hz and grows above 35 Hz") {
  struct Case { const char* m; double ms; };
  for (const Case& k : {Case{"0.0A", 8.0}, Case{"2.5A", 10.0}, Case{"avg", 9.0}}) {
    const E2 e = MakeE2(Config("poly3", k.m, k.ms), k.m);
    std::printf("E2 3rd Poly %g ms on %s |G_yr|:", k.ms, k.m);
    for (double f : {1.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 50.0}) std::printf(" %g:%.3f", f, e.Mag(f));
    std::printf("\n");
    for (double f = 5.0; f <= 25.0; f += 1.0) CHECK(e.Mag(f) < 1.0);
    double prev = e.Mag(35.0);
    for (double f = 36.0; f <= 50.0; f += 1.0) {
      CHECK(e.Mag(f) > prev);
      prev = e.Mag(f);
    }
    CHECK(e.Mag(50.0) > 1.1);
    CHECK(std::abs(e.Mag(1.0) - 1.0) < 0.01);  // good at low frequency
  }
}

TEST_CASE("E2: the lead compensator's magnitude grows above 10 Hz and its lag is under-compensated") {
  struct Case { const char* m; double ms; };
  for (const Case& k : {Case{"0.0A", 8.0}, Case{"2.5A", 10.0}, Case{"avg", 9.0}}) {
    const E2 e = MakeE2(Config("lead", k.m, k.ms), k.m);
    std::printf("E2 Lead %g ms on %s |G_yr| / lag [ms]:", k.ms, k.m);
    for (double f : {1.0, 5.0, 10.0, 20.0, 30.0, 50.0}) std::printf(" %g:%.3f/%.2f", f, e.Mag(f), e.Lag(f) * 1e3);
    std::printf("\n");
    CHECK(std::abs(e.Mag(1.0) - 1.0) < 0.01);
    double prev = e.Mag(10.0), prev_lag = e.Lag(10.0);
    for (double f = 11.0; f <= 30.0; f += 1.0) {  // the band the paper describes
      CHECK(e.Mag(f) > prev);
      CHECK(e.Lag(f) > prev_lag);
      prev = e.Mag(f), prev_lag = e.Lag(f);
    }
    CHECK(e.Mag(20.0) > 1.1);
    for (double f = 30.0; f <= 50.0; f += 1.0) CHECK(e.Mag(f) > 1.4);  // stays high (the plant rolls off)
  }
}

// ---------------------------------------------------------------------------------------------
// Offline time-domain tracking (docs/models.md section 10) on the linear ZOH plants, 60 s BLWN records
// (section 9, seed 1, as tracking_test.cpp), derivatives by Eqs. 20-22, scored by Eq. 31.

namespace {

constexpr std::size_t kSteps = 120000;  // 60 s
constexpr std::size_t kSettle = 200;    // 0.1 s start-up transient (see below)

struct Score {
  double full = 0.0;    // Eq. 31 over the whole record [%]
  double steady = 0.0;  // Eq. 31 from step kSettle on [%]
};

// Step indices as in docs/lockstep.md: y_k = C z_k depends on u_0 .. u_{k-1}; u_k uses r_k (and
// its Eqs. 20-22 derivatives) and y_k; u_k is held over [t_k, t_{k+1}).
Score Track(const ControllerConfig& cfg, const char* plant, const std::vector<double>& r, double current_A) {
  auto c = ctl::MakeTrackingController(cfg, kDt);
  const mdl::LinearServo servo = mdl::LinearServo::Make(ServoPreset(plant), kDt);
  mdl::LinearServoState state;
  ctl::ExtrapolationState past;
  sig::RmsErrorAccumulator full, steady;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const ctl::Derivatives d = ctl::StepDerivatives(&past, r[k], kDt);
    const double y = mdl::Output(servo, state);
    full.Add(r[k], y);
    if (k >= kSettle) steady.Add(r[k], y);
    mdl::Step(servo, &state, c->Step(d, {y, 0.0, current_A}).u_mm);
  }
  return {full.Percent(), steady.Percent()};
}

}  // namespace

// The BLWN record starts mid-motion (r_0 != 0 after the 2 s discard) while the plant starts at rest,
// so each run pays a start-up transient that depends on the generator's r_0 (tracking_test.cpp); the
// feedback of ff_lqg pays most (e_0 = -r_0 drives the estimator). The reference values of
// docs/models.md section 10 agree with our figures after the first 0.1 s (they were computed independently,
// with another generator, evidently without that transient), so those are asserted. Tolerance: 10 %
// relative, the spread of the independent FF computation against ours (0.46 vs 0.449 %, 1.33 vs
// 1.311 %: 2-3 %) with margin for a different noise record; every row sits within 5 %.
TEST_CASE("time domain: docs/models.md section 10 on the linear ZOH plants (0-5 Hz 2.78 mm, 0-15 Hz 0.595 mm)") {
  const std::vector<double> r5 = sig::Blwn(5.0, 2.78, kDt, kSteps, 1, 2.0);
  const std::vector<double> r15 = sig::Blwn(15.0, 0.595, kDt, kSteps, 1, 2.0);
  struct Row {
    const char* name;
    ControllerConfig cfg;
    const char* plant;
    double ref5, ref15;
  };
  ControllerConfig lp = Config("ff_lp", "0.0A");
  ControllerConfig bumpless = Config("bumpless_lp");
  const Row rows[] = {
      {"FF 0.0A (matching)", Config("ff", "0.0A"), "0.0A", 0.46, 1.33},
      {"FF avg + LQG", Config("ff_lqg", "avg"), "0.0A", 0.27, 1.87},
      {"FF avg + LQG", Config("ff_lqg", "avg"), "2.5A", 0.44, 3.22},
      {"3rd Poly 8ms", Config("poly3", "0.0A", 8.0), "0.0A", 0.63, 3.42},
      {"Lead Comp 8ms", Config("lead", "0.0A", 8.0), "0.0A", 1.20, 12.0},
      {"FF 0.0A + LP (318 Hz, Tustin)", lp, "0.0A", 2.33, 6.98},
      {"Bumpless + LP at 0 A", bumpless, "0.0A", 2.33, 6.98},
  };
  std::printf("Eq. 31 [%%], whole record / after 0.1 s (docs/models.md section 10 reference):\n");
  for (const Row& row : rows) {
    CAPTURE(row.name);
    CAPTURE(row.plant);
    const Score s5 = Track(row.cfg, row.plant, r5, 0.0), s15 = Track(row.cfg, row.plant, r15, 0.0);
    std::printf("  %-30s %s plant: 0-5 Hz %6.3f / %6.3f (%5.2f)   0-15 Hz %6.3f / %6.3f (%5.2f)\n", row.name,
                row.plant, s5.full, s5.steady, row.ref5, s15.full, s15.steady, row.ref15);
    CHECK(s5.steady == doctest::Approx(row.ref5).epsilon(0.10));
    CHECK(s15.steady == doctest::Approx(row.ref15).epsilon(0.10));
    CHECK(s5.full >= s5.steady * 0.99);  // the transient only adds
  }
  // The bumpless controller at 2.5 A is the 2.5 A design alone.
  CHECK(Track(bumpless, "2.5A", r15, 2.5).full == doctest::Approx(Track(Config("ff_lp", "2.5A"), "2.5A", r15, 0.0).full));
}

// ---------------------------------------------------------------------------------------------

TEST_CASE("Step() allocates nothing after construction, for every kind") {
  const std::vector<double> r = sig::Blwn(10.0, 1.0, kDt, 2000, 5, 0.1);
  for (const char* kind : {"none", "ff", "poly3", "lead", "ff_lp", "bumpless_lp", "ff_lqg"}) {
    CAPTURE(kind);
    auto c = ctl::MakeTrackingController(Config(kind), kDt);
    ctl::ExtrapolationState past;
    double sink = 0.0;
    const long before = rths_test::AllocationCount();
    for (std::size_t k = 0; k < r.size(); ++k) {
      sink += c->Step(ctl::StepDerivatives(&past, r[k], kDt), {0.9 * r[k], 1.0, 0.001 * k}).u_mm;
    }
    CHECK(rths_test::AllocationCount() - before == 0);
    CHECK(std::isfinite(sink));
  }
}

TEST_CASE("MakeTrackingController refuses bad designs with errors naming the scenario key") {
  struct Case {
    const char* kind;
    void (*edit)(ControllerConfig*);
    const char* key;
  };
  const Case cases[] = {
      {"unknown", [](ControllerConfig*) {}, "controller.kind"},
      {"poly3", [](ControllerConfig* c) { c->delay_ms = 16.0; }, "controller.delay_ms"},  // > max_delay_ms
      {"poly3", [](ControllerConfig* c) { c->delay_ms = 0.0; }, "controller.delay_ms"},
      {"lead", [](ControllerConfig* c) { c->delay_ms = -1.0; }, "controller.delay_ms"},
      {"lead", [](ControllerConfig* c) { c->lead_tp_ms = 0.0; }, "controller.lead_tp_ms"},
      {"ff", [](ControllerConfig* c) { c->model.c = std::nan(""); }, "controller.model"},
      {"ff_lp", [](ControllerConfig* c) { c->lp_cutoff_hz = 1000.0; }, "controller.lp_cutoff_hz"},
      {"ff_lp", [](ControllerConfig* c) { c->lp_order = 2; }, "controller.lp_order"},
      {"ff_lp", [](ControllerConfig* c) { c->model.K = -1.0; }, "controller.model"},
      {"bumpless_lp", [](ControllerConfig* c) { c->model_high.p = 0.0; }, "controller.model_high"},
      {"bumpless_lp", [](ControllerConfig* c) { c->model_low.b = -2.0; }, "controller.model_low"},
      {"bumpless_lp", [](ControllerConfig* c) { c->current_high_A = 0.0; }, "controller.current_high_A"},
      {"ff_lqg", [](ControllerConfig* c) { c->lqg.q = 0.0; }, "controller.lqg.q"},
      {"ff_lqg", [](ControllerConfig* c) { c->lqg.V = -1.0; }, "controller.lqg.V"},
      {"ff_lqg", [](ControllerConfig* c) { c->model.p = -151.7; }, "controller.model"},
  };
  for (const Case& k : cases) {
    ControllerConfig cfg = Config(k.kind);
    k.edit(&cfg);
    CAPTURE(k.kind);
    CAPTURE(k.key);
    bool thrown = false;
    try {
      ctl::MakeTrackingController(cfg, kDt);
    } catch (const rths::Error& e) {
      thrown = true;
      CHECK(e.where() == k.key);
      CHECK(std::string(e.what()).find(k.key) != std::string::npos);
    }
    CHECK(thrown);
  }
}

TEST_CASE("DesignController: every kind designs, reports and serialises; ff_lqg carries its loop margins") {
  for (const char* kind : {"none", "ff", "poly3", "lead", "ff_lp", "bumpless_lp", "ff_lqg"}) {
    CAPTURE(kind);
    const ctl::DesignSummary d = ctl::DesignController(Config(kind), kDt);
    const nlohmann::json j = d.ToJson();
    CHECK(j["kind"] == kind);
    CHECK(j["plants"].size() == 3);
    CHECK(d.Report().find(std::string("controller: ") + kind) == 0);
    CHECK(j.contains("lqg") == (std::string(kind) == "ff_lqg"));
    CHECK(j.contains("poly3") == (std::string(kind) == "poly3"));
    CHECK(j.contains("lowpass") == (std::string(kind).find("_lp") != std::string::npos));
  }
  const ctl::DesignSummary d = ctl::DesignController(Config("ff_lqg"), kDt);
  REQUIRE(d.plants[1].loop.has_value());
  CHECK(d.plants[1].name == "avg");
  CHECK(d.plants[1].loop->critical.phase_margin_deg == doctest::Approx(63.3).epsilon(0.001));
  CHECK_THROWS_AS(ctl::DesignController(Config("pid"), kDt), rths::Error);
}
