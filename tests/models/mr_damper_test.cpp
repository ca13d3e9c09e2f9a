// MR damper (Eqs. 32-39, Table 3): E6 characterisation peaks, dissipation, current law.
#include <cmath>
#include <numbers>
#include <vector>

#include <doctest/doctest.h>

#include "core/error.h"
#include "models/mr_damper.h"

using namespace rths::models;

namespace {

constexpr double kPi = std::numbers::pi;

// E6 motion: x = 25.4 sin(2 pi t) mm.
struct Sine {
  double amplitude_mm = 25.4;
  double frequency_hz = 1.0;
};
void SineMotion(double t, void* ctx, double* x, double* xdot) {
  const auto* s = static_cast<const Sine*>(ctx);
  const double w = 2 * kPi * s->frequency_hz;
  *x = s->amplitude_mm * std::sin(w * t);
  *xdot = s->amplitude_mm * w * std::cos(w * t);
}

struct Run {
  std::vector<double> t, f, v;
};
// Three cycles at a constant current, sampled every dt.
Run Simulate(double current_A, double dt = 0.0005, double rtol = 1e-8) {
  Sine sine;
  MrDamperStepper stepper(MrDamperParams::Table3(), &SineMotion, &sine, rtol);
  MrDamperState s;
  Run r;
  const int n = static_cast<int>(std::lround(3.0 / dt));
  for (int k = 0; k <= n; ++k) {
    const double t = k * dt;
    double x, v;
    SineMotion(t, &sine, &x, &v);
    r.t.push_back(t);
    r.f.push_back(stepper.ForceKn(t, current_A, s));
    r.v.push_back(v);
    if (k < n) stepper.Advance(t, t + dt, current_A, &s);
  }
  return r;
}

double PeakAfter(const Run& r, double t_from) {
  double peak = 0.0;
  for (size_t k = 0; k < r.t.size(); ++k)
    if (r.t[k] >= t_from) peak = std::max(peak, std::abs(r.f[k]));
  return peak;
}

}  // namespace

TEST_CASE("E6: peak force at 25.4 mm, 1 Hz within 2 % of the reference") {
  const double current[] = {0.0, 0.5, 1.0, 1.5, 2.0, 2.5};
  const double reference_kN[] = {18.3, 77.9, 139.6, 166.8, 179.7, 187.0};  // docs/experiments.md E6
  for (int i = 0; i < 6; ++i) {
    CAPTURE(current[i]);
    const double peak = PeakAfter(Simulate(current[i]), 1.0);  // 2nd and 3rd cycles
    MESSAGE("i = " << current[i] << " A: peak " << peak << " kN (reference " << reference_kN[i]
                   << ")");
    CHECK(peak == doctest::Approx(reference_kN[i]).epsilon(0.02));
  }
}

TEST_CASE("the damper dissipates: mean F x' over a cycle is positive, and F opposes x' at speed") {
  for (double i : {0.0, 1.0, 2.5}) {
    CAPTURE(i);
    const Run r = Simulate(i);
    double work = 0.0;  // kN mm over the third cycle (trapezoid)
    for (size_t k = 1; k < r.t.size(); ++k)
      if (r.t[k] > 2.0)
        work += 0.5 * (r.f[k] * r.v[k] + r.f[k - 1] * r.v[k - 1]) * (r.t[k] - r.t[k - 1]);
    CHECK(work > 0.0);
    // Near peak velocity the force has the sign of the velocity (it resists the motion).
    for (size_t k = 0; k < r.t.size(); ++k)
      if (r.t[k] > 1.0 && std::abs(r.v[k]) > 0.9 * 2 * kPi * 25.4) CHECK(r.f[k] * r.v[k] > 0.0);
  }
}

TEST_CASE("output sampling does not change the answer (CVODE tolerance, not the step, rules)") {
  const Run fine = Simulate(1.0, 0.0005), coarse = Simulate(1.0, 0.002);
  // Compare at the common instants t = 2 ms * j.
  double max_diff = 0.0;
  for (size_t j = 0; j < coarse.t.size(); ++j)
    max_diff = std::max(max_diff, std::abs(coarse.f[j] - fine.f[4 * j]));
  MESSAGE("max |F(2 ms steps) - F(0.5 ms steps)| = " << max_diff << " kN");
  CHECK(max_diff < 5e-4);  // kN, against forces of ~140 kN
}

TEST_CASE("current law (Eqs. 35-39)") {
  const MrDamperParams p = MrDamperParams::Table3();
  const MrDamperCoefficients k0 = CoefficientsAt(p, 0.0);
  CHECK(k0.alpha == doctest::Approx(p.alpha_a).epsilon(1e-14));
  CHECK(k0.c0 == doctest::Approx(p.c0_a).epsilon(1e-14));
  CHECK(k0.c1 == doctest::Approx(p.c1_a).epsilon(1e-14));
  CHECK(k0.beta == doctest::Approx(p.beta_a).epsilon(1e-14));
  CHECK(k0.gamma == doctest::Approx(p.gamma_a).epsilon(1e-14));
  // At 2.5 A each coefficient equals its b-value up to the exponential tail (a - b) e^{-2.5 c}.
  const MrDamperCoefficients k25 = CoefficientsAt(p, 2.5);
  struct Item {
    double got, a, b, c;
  };
  for (const Item& it : {Item{k25.alpha, 0.11, 0.55, 1.0}, Item{k25.c0, 0.080, 0.32, 1.5},
                         Item{k25.c1, 3.0, 15.0, 2.0}, Item{k25.beta, 0.050, 0.0020, 5.2},
                         Item{k25.gamma, 0.050, 0.0020, 5.2}}) {
    const double tail = std::abs(it.a - it.b) * std::exp(-2.5 * it.c);
    CHECK(std::abs(it.got - it.b) <= tail * (1 + 1e-12));
    CHECK(std::abs(it.got - it.b) >= tail * (1 - 1e-12));
  }
  // Monotone in the current between the extremes.
  CHECK(CoefficientsAt(p, 1.0).alpha > k0.alpha);
  CHECK(CoefficientsAt(p, 1.0).alpha < k25.alpha);
  CHECK(k25.A == 300.0);
  CHECK(k25.n == 2.0);
}

TEST_CASE("rates and force: closed forms at a chosen state") {
  const MrDamperCoefficients k = CoefficientsAt(MrDamperParams::Table3(), 0.0);
  const MrDamperState s{1.0, 20.0};
  const double x = 5.0, xdot = 100.0;
  const double ydot = (k.alpha * 20.0 + k.c0 * xdot) / (k.c0 + k.c1);
  const double v = xdot - ydot;
  const MrDamperRates r = DamperRates(k, s, x, xdot);
  CHECK(r.ydot_mm_s == doctest::Approx(ydot).epsilon(1e-14));
  const double zdot = -k.gamma * std::abs(v) * 400.0 - k.beta * v * 400.0 + 300.0 * v;
  CHECK(r.zdot_mm_s == doctest::Approx(zdot).epsilon(1e-12));
  // Eq. 34 equals c1 y' (Eq. 32) when k1 = 0.
  CHECK(DamperForceKn(k, s, x, xdot) == doctest::Approx(k.c1 * ydot).epsilon(1e-12));
  // The general-n branch agrees with the n = 2 one.
  MrDamperCoefficients kn = k;
  kn.n = 2.0 + 1e-12;
  CHECK(DamperRates(kn, s, x, xdot).zdot_mm_s == doctest::Approx(r.zdot_mm_s).epsilon(1e-9));
  // Bouc-Wen saturation: at z = sqrt(A / (beta + gamma)) and v > 0, z' = 0.
  const MrDamperState sat{0.0, std::sqrt(k.A / (k.beta + k.gamma))};
  const MrDamperRates rs = DamperRates(k, sat, 0.0, 1e4);  // v = x' - y' > 0 here
  CHECK(std::abs(rs.zdot_mm_s) < 1e-8 * k.A * 1e4);
}

TEST_CASE("OdeStepper: closed form, stop time, and errors") {
  // x' = -lambda x (stiff: lambda = 1e5 /s) and y' = cos(t): x(t) = x0 e^{-lambda t}, y = sin t.
  static constexpr double kLambda = 1e5;
  auto rhs = [](double t, const double* x, double* xdot, void*) {
    xdot[0] = -kLambda * x[0];
    xdot[1] = std::cos(t);
    return 0;
  };
  OdeStepper ode(2, 1e-10, 1e-14, rhs, nullptr, OdeMethod::kBdf);  // stiff: BDF
  double x[2] = {1.0, 0.0};
  ode.Advance(0.0, 1e-4, x);
  CHECK(x[0] == doctest::Approx(std::exp(-10.0)).epsilon(1e-6));
  ode.Advance(1e-4, 1.0, x);
  CHECK(x[1] == doctest::Approx(std::sin(1.0)).epsilon(1e-8));
  CHECK_THROWS_AS(ode.Advance(1.0, 1.0, x), rths::Error);
  // The explicit default on the same closed form over a step where it is not stiff
  // (|h lambda| <= 1 for h = 1e-5 s); a stiff interval it cannot cross, and says so.
  OdeStepper erk(2, 1e-10, 1e-14, rhs, nullptr);
  CHECK(erk.method() == OdeMethod::kErk);
  double e[2] = {1.0, 0.0};
  erk.Advance(0.0, 1e-5, e);
  CHECK(e[0] == doctest::Approx(std::exp(-1.0)).epsilon(1e-8));
  CHECK(e[1] == doctest::Approx(std::sin(1e-5)).epsilon(1e-8));
  CHECK_THROWS_WITH_AS(erk.Advance(1e-4, 1.0, e), doctest::Contains("ERKStep failed"), rths::Error);

  auto failing = [](double t, const double*, double* xdot, void*) {
    xdot[0] = 1.0;
    return t > 0.5 ? -1 : 0;
  };
  OdeStepper bad(1, 1e-8, 1e-10, failing, nullptr, OdeMethod::kBdf);
  double z[1] = {0.0};
  CHECK_THROWS_WITH_AS(bad.Advance(0.0, 1.0, z), doctest::Contains("CV_RHSFUNC_FAIL"), rths::Error);
  OdeStepper bad_erk(1, 1e-8, 1e-10, failing, nullptr);
  z[0] = 0.0;
  CHECK_THROWS_WITH_AS(bad_erk.Advance(0.0, 1.0, z), doctest::Contains("RHSFUNC_FAIL"), rths::Error);
  CHECK_THROWS_AS(OdeStepper(0, 1e-8, 1e-10, rhs, nullptr), rths::Error);
  CHECK_THROWS_AS(OdeStepper(2, -1.0, 1e-10, rhs, nullptr), rths::Error);
}

TEST_CASE("parameter validation") {
  MrDamperParams p;
  p.c1_a = 0.0;
  CHECK_THROWS_AS(p.Validate(), rths::Error);
  p = MrDamperParams{};
  p.n = 0.5;
  CHECK_THROWS_WITH_AS(p.Validate(), doctest::Contains("n"), rths::Error);
  Sine sine;
  p.n = 2.0;
  CHECK_NOTHROW(MrDamperStepper(p, &SineMotion, &sine));
  CHECK_THROWS_AS(MrDamperStepper(p, nullptr, &sine), rths::Error);
}
