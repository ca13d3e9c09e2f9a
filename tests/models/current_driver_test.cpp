// MR damper current dynamics (Eq. 40 + 75 Hz Butterworth, lib/models/current_driver.h): DC gain,
// Eq. 40's 1/9 jump, time constants, exact ZOH against an independent fine integration, exact
// constancy at a constant current; and the rigs with current dynamics on.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <doctest/doctest.h>

#include "core/error.h"
#include "models/current_driver.h"
#include "models/linear_rig.h"
#include "models/rig.h"

using namespace rths::models;

namespace {

constexpr double kDt = 0.0005;
constexpr double kPi = std::numbers::pi;
const double kWn = 2 * kPi * 75.0;
const double kZeta = 1.0 / std::sqrt(2.0);

// Independent realisation of the series connection, integrated with RK4 at a fine step:
// Eq. 40 as m' = -pi m + i, i_40 = i / 9 + (8 pi / 9) m; low-pass as p'' = w^2 (i_40 - p) - 2 z w p'.
struct Series {
  double m = 0, p = 0, pd = 0;
};
void Rates(const Series& s, double i, Series* d) {
  const double i40 = i / 9.0 + 8.0 * kPi / 9.0 * s.m;
  d->m = -kPi * s.m + i;
  d->p = s.pd;
  d->pd = kWn * kWn * (i40 - s.p) - 2 * kZeta * kWn * s.pd;
}
void Rk4(Series* s, double i, double h) {
  Series k1, k2, k3, k4;
  const auto add = [](const Series& a, const Series& d, double f) {
    return Series{a.m + f * d.m, a.p + f * d.p, a.pd + f * d.pd};
  };
  Rates(*s, i, &k1);
  Rates(add(*s, k1, h / 2), i, &k2);
  Rates(add(*s, k2, h / 2), i, &k3);
  Rates(add(*s, k3, h), i, &k4);
  s->m += h / 6 * (k1.m + 2 * k2.m + 2 * k3.m + k4.m);
  s->p += h / 6 * (k1.p + 2 * k2.p + 2 * k3.p + k4.p);
  s->pd += h / 6 * (k1.pd + 2 * k2.pd + 2 * k3.pd + k4.pd);
}

}  // namespace

TEST_CASE("DC gain 1; 75 Hz Butterworth corner; Eq. 40 alone") {
  const CurrentDriver d = CurrentDriver::Make({}, kDt);
  CHECK(d.DcGain() == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(std::abs(d.FrequencyResponse(0.0) - 1.0) < 1e-14);
  // At 75 Hz the low-pass is at -3 dB (|LP(j w_n)| = 1 / (2 zeta)) and -90 deg.
  const std::complex<double> s(0.0, kWn);
  const std::complex<double> eq40 = (s + 9.0 * kPi) / (9.0 * (s + kPi));
  const std::complex<double> lp = d.FrequencyResponse(75.0) / eq40;
  CHECK(std::abs(lp) == doctest::Approx(1.0 / std::sqrt(2.0)).epsilon(1e-12));
  CHECK(std::arg(lp) == doctest::Approx(-kPi / 2).epsilon(1e-12));
  // At high frequency Eq. 40 tends to 1/9.
  const std::complex<double> hi(0.0, 2 * kPi * 1e5);
  CHECK(std::abs((hi + 9.0 * kPi) / (9.0 * (hi + kPi))) == doctest::Approx(1.0 / 9).epsilon(1e-6));

  // A unit step held: after 10 s within 1e-13; after about 11 s the deviation falls below
  // kSettledA and the current is exactly 1 again.
  CurrentDriverState st;
  for (int k = 0; k < 20000; ++k) Step(d, &st, 1.0);
  CHECK(EffectiveCurrentA(d, st) == doctest::Approx(1.0).epsilon(1e-13));
  CHECK(DriverOutputA(d, st) == doctest::Approx(1.0).epsilon(1e-13));
  CHECK(!AtSteadyState(st));
  for (int k = 0; k < 4000; ++k) Step(d, &st, 1.0);
  CHECK(AtSteadyState(st));
  CHECK(EffectiveCurrentA(d, st) == 1.0);
}

TEST_CASE("a step: Eq. 40 jumps by 1/9 at once, i_c is continuous, time constants 1/pi and the low-pass") {
  const CurrentDriver d = CurrentDriver::Make({}, kDt);
  CurrentDriverState st = SteadyState(0.0);
  Hold(d, &st, 1.0);
  // Before the low-pass: the driver's output jumps to 1/9 of the step (Eq. 40 at s -> inf).
  CHECK(DriverOutputA(d, st) == doctest::Approx(1.0 / 9.0).epsilon(1e-14));
  // After it: continuous, still 0 at t_k.
  CHECK(std::abs(EffectiveCurrentA(d, st)) < 1e-15);
  CHECK(std::abs(EffectiveCurrentAt(d, st, 0.0)) < 1e-15);

  // The slow tail: 1 - i_c(t) decays with time constant 1 / pi = 318 ms (Eq. 40's pole) once the
  // low-pass has settled (its modes decay as e^{-zeta w_n t}, zeta w_n = 333 1/s).
  const double t1 = 0.2, t2 = 0.4;
  const double ratio = (1 - EffectiveCurrentAt(d, st, t2)) / (1 - EffectiveCurrentAt(d, st, t1));
  CHECK(std::log(ratio) / (t1 - t2) == doctest::Approx(kPi).epsilon(1e-9));
  // ... and its amplitude is Eq. 40's 8/9 times LP(-pi) (the low-pass's gain at s = -pi).
  const double lp_at_minus_pi = kWn * kWn / (kPi * kPi - 2 * kZeta * kWn * kPi + kWn * kWn);
  CHECK((1 - EffectiveCurrentAt(d, st, t1)) * std::exp(kPi * t1) ==
        doctest::Approx(8.0 / 9.0 * lp_at_minus_pi).epsilon(1e-9));
  // The fast part, i_c minus that tail, is the low-pass pair: it decays by e^{-zeta w_n T_d}
  // over one damped period T_d = 2 pi / (w_n sqrt(1 - zeta^2)).
  const auto fast = [&](double t) {
    return EffectiveCurrentAt(d, st, t) - (1 - 8.0 / 9.0 * lp_at_minus_pi * std::exp(-kPi * t));
  };
  const double td = 2 * kPi / (kWn * std::sqrt(1 - kZeta * kZeta));
  for (double t : {0.0005, 0.0013, 0.004}) {
    CHECK(fast(t + td) / fast(t) == doctest::Approx(std::exp(-kZeta * kWn * td)).epsilon(1e-7));
  }
  // 20 ms after the step the low-pass has followed Eq. 40's output to within 1e-3.
  CHECK(std::abs(fast(0.02)) < 1e-3);
}

TEST_CASE("exact ZOH: the samples match a fine RK4 integration of an independent realisation") {
  const CurrentDriver d = CurrentDriver::Make({}, kDt);
  CurrentDriverState st;  // at rest, 0 A
  Series ref;
  double max_err = 0.0, max_err_within = 0.0;
  const int sub = 50;
  for (int k = 0; k < 3000; ++k) {
    // A pulse train with a few levels (0, 2.5, 1, 0.3 A) switching every 0.1 s.
    const double levels[] = {2.5, 0.0, 1.0, 0.3};
    const double i = levels[(k / 200) % 4];
    Hold(d, &st, i);
    for (int j = 0; j < sub; ++j) {
      if (j == sub / 2) {
        max_err_within = std::max(max_err_within,
                                  std::abs(EffectiveCurrentAt(d, st, kDt / 2) - ref.p));
      }
      Rk4(&ref, i, kDt / sub);
    }
    Advance(d, &st);
    max_err = std::max(max_err, std::abs(EffectiveCurrentA(d, st) - ref.p));
    // Eq. 40's output alone is the independent realisation's i_40.
    CHECK(DriverOutputA(d, st) ==
          doctest::Approx(i / 9.0 + 8.0 * kPi / 9.0 * ref.m).epsilon(1e-9));
  }
  MESSAGE("max |i_c - RK4| at samples " << max_err << " A, mid-step " << max_err_within << " A");
  CHECK(max_err < 1e-9);
  CHECK(max_err_within < 1e-9);
}

TEST_CASE("a constant current stays exactly constant, and Hold keeps i_c continuous") {
  const CurrentDriver d = CurrentDriver::Make({}, kDt);
  CurrentDriverState st = SteadyState(1.7);
  bool exact = true;
  for (int k = 0; k < 20000; ++k) {
    Step(d, &st, 1.7);
    exact = exact && EffectiveCurrentA(d, st) == 1.7 && EffectiveCurrentAt(d, st, 0.3e-3) == 1.7;
  }
  CHECK(exact);
  CHECK(AtSteadyState(st));
  // Continuity across a change of command, mid-transient.
  for (int k = 0; k < 37; ++k) Step(d, &st, 0.2);
  const double before = EffectiveCurrentA(d, st);
  Hold(d, &st, 2.5);
  CHECK(EffectiveCurrentA(d, st) == doctest::Approx(before).epsilon(1e-14));
}

TEST_CASE("Make validates") {
  CHECK_THROWS_AS(CurrentDriver::Make({}, 0.0), rths::Error);
  CurrentDriverParams p;
  p.lowpass_zeta = 1.0;
  CHECK_THROWS_AS(CurrentDriver::Make(p, kDt), rths::Error);
  p = {};
  p.lowpass_hz = -75.0;
  CHECK_THROWS_AS(CurrentDriver::Make(p, kDt), rths::Error);
  p = {};
  p.lag_zero_rad_s = p.lag_pole_rad_s;
  CHECK_THROWS_AS(CurrentDriver::Make(p, kDt), rths::Error);
}

namespace {

double Command(int k) { return 10.0 * std::sin(2 * kPi * 2.0 * k * kDt); }  // mm

}  // namespace

TEST_CASE("linear rig: current dynamics at a constant current change nothing, bit for bit") {
  const rths::models::ServoModel3 avg{};  // Eq. 30
  for (double current : {0.0, 1.25, 2.5}) {
    const LinearRig plain = LinearRig::Make(avg, kDt, true);
    const LinearRig dyn = LinearRig::Make(avg, kDt, true, MrDamperParams::Table3(), 1e-8, true);
    LinearRigStepper sp(plain), sd(dyn);
    LinearRigState a, b;
    b.current = SteadyState(current);  // the current was set before the test
    bool same = true;
    for (int k = 0; k < 2000; ++k) {
      sp.Step(&a, Command(k), current);
      sd.Step(&b, Command(k), current);
      same = same && MeasuredForceKn(plain, a, current) == MeasuredForceKn(dyn, b) &&
             a.damper.y_mm == b.damper.y_mm && a.damper.z_mm == b.damper.z_mm &&
             EffectiveCurrentA(dyn, b) == current;
    }
    CHECK(same);
  }
}

TEST_CASE("linear rig: a current pulse reaches the damper through Eq. 40 and the low-pass") {
  const rths::models::ServoModel3 avg{};
  const LinearRig plain = LinearRig::Make(avg, kDt, true);
  const LinearRig dyn = LinearRig::Make(avg, kDt, true, MrDamperParams::Table3(), 1e-8, true);
  const CurrentDriver driver = CurrentDriver::Make({}, kDt);
  LinearRigStepper sp(plain), sd(dyn);
  LinearRigState a, b;
  CurrentDriverState ref;
  double sum_plain = 0, sum_dyn = 0;
  bool same_current = true;
  for (int k = 0; k < 2000; ++k) {  // 0 A for 0.25 s, then 2.5 A
    const double i = k < 500 ? 0.0 : 2.5;
    sp.Step(&a, Command(k), i);
    sd.Step(&b, Command(k), i);
    Step(driver, &ref, i);
    same_current = same_current && EffectiveCurrentA(dyn, b) == EffectiveCurrentA(driver, ref);
    if (k >= 500 && k < 700) {
      sum_plain += std::abs(MeasuredForceKn(plain, a, i));
      sum_dyn += std::abs(MeasuredForceKn(dyn, b));
    }
  }
  CHECK(same_current);
  // Over the 100 ms after the switch the effective current climbs from 1/9 to about 0.34 of
  // 2.5 A (1 - (8/9) e^{-pi t}), so the damper force stays well below the instant-switch force.
  MESSAGE("mean |f| over 100 ms after 0 -> 2.5 A: " << sum_dyn / 200 << " kN with current "
          "dynamics, " << sum_plain / 200 << " kN with an instant switch");
  CHECK(sum_dyn < 0.8 * sum_plain);
}

TEST_CASE("Rig (linear): current_A is the effective current, starting steady at the first command") {
  rths::models::PlantConfig cfg;  // linear, mr_damper, current_dynamics on
  auto rig = MakeRig(cfg, kDt);
  CHECK(rig->k() == 0);
  CHECK(rig->current_A() == 0.0);  // at rest, nothing commanded yet
  for (int k = 0; k < 100; ++k) rig->Step(Command(k), 2.5);
  CHECK(rig->current_A() == 2.5);  // constant from the start: exactly the command
  for (int k = 100; k < 101; ++k) rig->Step(Command(k), 0.0);
  CHECK(rig->current_A() > 2.49);  // one step after switching off: i_c is continuous
  CHECK(rig->current_A() < 2.5);
  CHECK(rig->k() == 101);
}
