// Linear rig (servo Eqs. 28-30 + MR damper Eqs. 32-39): servo authority, damper force against an
// independent drive, determinism, and an allocation-free step.
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <numbers>
#include <vector>

#include <doctest/doctest.h>

#include "core/error.h"
#include "models/linear_rig.h"

using namespace rths::models;
using rths::models::ServoModel3;

// Count every heap allocation of the process (CVODE uses malloc, C++ new ends in malloc).
#include "alloc_counter.h"

namespace {

constexpr double kDt = 0.0005;
constexpr double kPi = std::numbers::pi;
const ServoModel3 kModel00{1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};  // Eq. 28

double Command(int k) { return 25.4 * std::sin(2 * kPi * 1.0 * k * kDt); }  // E6 sine, mm

struct History {
  std::vector<double> y, f;
  std::vector<LinearRigState> states;
};

History Run(const LinearRig& rig, int steps, double current_A) {
  LinearRigStepper stepper(rig);
  LinearRigState s;
  History h;
  for (int k = 0; k < steps; ++k) {
    h.states.push_back(s);
    h.y.push_back(MeasuredDisplacementMm(rig, s));
    h.f.push_back(MeasuredForceKn(rig, s, current_A));
    stepper.Step(&s, Command(k), current_A);
  }
  return h;
}

// The actuator's steady-state motion under the sine command, from the ZOH frequency response.
struct SteadySine {
  double amplitude_mm, phase_rad;
};
void SteadyMotion(double t, void* ctx, double* x, double* xdot) {
  const auto* m = static_cast<const SteadySine*>(ctx);
  *x = m->amplitude_mm * std::sin(2 * kPi * t + m->phase_rad);
  *xdot = m->amplitude_mm * 2 * kPi * std::cos(2 * kPi * t + m->phase_rad);
}

}  // namespace

TEST_CASE("without a damper the rig is exactly the linear servo") {
  const LinearRig rig = LinearRig::Make(kModel00, kDt, false);
  const History h = Run(rig, 2000, 0.0);
  LinearServoState ref;
  for (int k = 0; k < 2000; ++k) {
    CHECK(h.y[k] == Output(rig.servo, ref));  // bit-identical
    CHECK(h.f[k] == 0.0);
    Step(rig.servo, &ref, Command(k));
  }
}

TEST_CASE("1 Hz, 25.4 mm sine through the servo at 0 A") {
  const LinearRig rig = LinearRig::Make(kModel00, kDt, true);
  const int steps = 6001;  // 3 s
  const History h = Run(rig, steps, 0.0);

  // The damper does not load the linear servo: y is bit-identical to LinearServo.
  LinearServoState ref;
  bool same = true;
  for (int k = 0; k < steps; ++k) {
    same = same && h.y[k] == Output(rig.servo, ref);
    Step(rig.servo, &ref, Command(k));
  }
  CHECK(same);

  // Independent drive: the damper alone (MrDamperStepper) under the servo's steady-state motion,
  // amplitude |G(j 2 pi)| 25.4 mm and phase arg G (ZOH). After the transients (t >= 1 s) both
  // forces must agree sample by sample.
  const std::complex<double> g = FrequencyResponse(rig.servo, 1.0, true);
  SteadySine motion{25.4 * std::abs(g), std::arg(g)};
  MrDamperStepper damper(rig.damper, &SteadyMotion, &motion, 1e-9);
  MrDamperState ds;
  double peak = 0.0, peak_ref = 0.0, max_diff = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double t = k * kDt;
    if (t >= 1.0) {
      const double f_ref = damper.ForceKn(t, 0.0, ds);
      peak = std::max(peak, std::abs(h.f[k]));
      peak_ref = std::max(peak_ref, std::abs(f_ref));
      max_diff = std::max(max_diff, std::abs(h.f[k] - f_ref));
    }
    if (k + 1 < steps) damper.Advance(t, t + kDt, 0.0, &ds);
  }
  MESSAGE("rig peak " << peak << " kN, steady-state drive " << peak_ref
                      << " kN, max sample difference " << max_diff << " kN; E6 (no servo) 18.3");
  CHECK(max_diff < 1e-3);  // kN
  CHECK(peak == doctest::Approx(peak_ref).epsilon(1e-3));
  // The servo attenuates by 0.3 % at 1 Hz, so the peak stays within 2 % of E6's 18.3 kN,
  // slightly below it.
  CHECK(peak == doctest::Approx(18.3).epsilon(0.02));
  CHECK(peak < 18.3 * 1.001);

  // Repeating the run is bit-identical.
  const History again = Run(rig, steps, 0.0);
  CHECK(again.f == h.f);
  CHECK(again.y == h.y);
}

TEST_CASE("a step depends only on (state, u, i): re-answering step k from its state") {
  const LinearRig rig = LinearRig::Make(kModel00, kDt, true);
  const History h = Run(rig, 1500, 1.0);
  LinearRigStepper stepper(rig);  // fresh, and then with a different history
  for (int k : {1499, 700, 1200, 3}) {
    LinearRigState s = h.states[k - 1];
    stepper.Step(&s, Command(k - 1), 1.0);
    CHECK(s.damper.y_mm == h.states[k].damper.y_mm);
    CHECK(s.damper.z_mm == h.states[k].damper.z_mm);
    CHECK(s.servo.z == h.states[k].servo.z);
  }
}

TEST_CASE("Step allocates nothing; timing") {
  const LinearRig rig = LinearRig::Make(kModel00, kDt, true);
  LinearRigStepper stepper(rig);
  LinearRigState s;
  const int steps = 4000;
  const long before = rths_test::AllocationCount();
  const auto t0 = std::chrono::steady_clock::now();
  double sum = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double current = (k / 1000) % 2 ? 2.5 : 0.0;  // 0.5 Hz pulse
    stepper.Step(&s, Command(k), current);
    sum += MeasuredForceKn(rig, s, current);
  }
  const auto t1 = std::chrono::steady_clock::now();
  const long allocations = rths_test::AllocationCount() - before;
  const double us = std::chrono::duration<double, std::micro>(t1 - t0).count() / steps;
  MESSAGE("LinearRig step with damper: " << us << " us (mean over " << steps << " steps)");
  CHECK(allocations == 0);
  CHECK(std::isfinite(sum));
}

TEST_CASE("Make validates") {
  CHECK_THROWS_AS(LinearRig::Make(kModel00, kDt, true, MrDamperParams::Table3(), 0.0), rths::Error);
  CHECK_THROWS_AS(LinearRig::Make(kModel00, -1.0, true), rths::Error);
  MrDamperParams bad;
  bad.c0_a = -1.0;
  CHECK_THROWS_AS(LinearRig::Make(kModel00, kDt, true, bad), rths::Error);
}
