// The MR damper's step integrator (OdeStepper, lib/models/ode.h) against a tight-tolerance
// reference: CVODE's BDF at rtol 1e-12. The default (ARKODE Dormand-Prince 5(4) at rtol 1e-8)
// must keep the force error below 0.1 % (RMS relative and peak relative) on the damper's own test
// motion and on motions nobody tuned it on: the Fig. 5 sine at every current, a faster small sine,
// a BLWN displacement at 0 A and 2.5 A, and a pulsed current. And a step re-answered from its
// state reproduces it bit for bit, whatever ran in between.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "models/mr_damper.h"
#include "signal/blwn.h"

using namespace rths::models;

namespace {

constexpr double kDt = 0.0005;  // the lockstep step [s]

// x(t) linear over each step [t_k, t_k+1] between samples (the "ideal" rig's motion), or a sine.
struct Motion {
  const std::vector<double>* x_mm = nullptr;  // sampled motion; null: the sine below
  std::size_t k = 0;                          // the step being integrated
  double amplitude_mm = 25.4, frequency_hz = 1.0;
};
void MotionAt(double t, void* ctx, double* x, double* xdot) {
  const auto* m = static_cast<const Motion*>(ctx);
  if (m->x_mm) {
    const std::vector<double>& xs = *m->x_mm;
    const double v = (xs[m->k + 1] - xs[m->k]) / kDt;
    *x = xs[m->k] + v * (t - static_cast<double>(m->k) * kDt);
    *xdot = v;
    return;
  }
  const double w = 2 * std::numbers::pi * m->frequency_hz;
  *x = m->amplitude_mm * std::sin(w * t);
  *xdot = m->amplitude_mm * w * std::cos(w * t);
}

using CurrentAt = double (*)(std::size_t k);

// The force at every sample of n steps from rest.
std::vector<double> Forces(Motion motion, std::size_t n, CurrentAt current, double rtol,
                           OdeMethod method) {
  MrDamperStepper stepper(MrDamperParams::Table3(), &MotionAt, &motion, rtol, method);
  MrDamperState s;
  std::vector<double> f;
  f.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    motion.k = k;
    const double t = static_cast<double>(k) * kDt;
    f.push_back(stepper.ForceKn(t, current(k), s));
    stepper.Advance(t, t + kDt, current(k), &s);
  }
  return f;
}

struct ForceError {
  double rms_rel = 0, peak_rel = 0;  // rms(F - F_ref) / rms(F_ref), max|F - F_ref| / max|F_ref|
};
ForceError Compare(const std::vector<double>& f, const std::vector<double>& ref) {
  double e2 = 0, r2 = 0, e_max = 0, r_max = 0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const double e = f[k] - ref[k];
    e2 += e * e;
    r2 += ref[k] * ref[k];
    e_max = std::max(e_max, std::abs(e));
    r_max = std::max(r_max, std::abs(ref[k]));
  }
  return {std::sqrt(e2 / r2), e_max / r_max};
}

// Checks the default integrator against the reference; reports the old default (BDF at 1e-8) too.
void CheckAccuracy(const std::string& name, const Motion& motion, std::size_t n, CurrentAt current) {
  const std::vector<double> ref = Forces(motion, n, current, 1e-12, OdeMethod::kBdf);
  const ForceError erk = Compare(Forces(motion, n, current, 1e-8, OdeMethod::kErk), ref);
  const ForceError bdf = Compare(Forces(motion, n, current, 1e-8, OdeMethod::kBdf), ref);
  MESSAGE(name << ": ERK rtol 1e-8 RMS " << erk.rms_rel << ", peak " << erk.peak_rel
               << "; BDF rtol 1e-8 RMS " << bdf.rms_rel << ", peak " << bdf.peak_rel);
  CHECK(erk.rms_rel < 1e-3);
  CHECK(erk.peak_rel < 1e-3);
  CHECK(erk.peak_rel > 0.0);  // a different integrator: if this is exactly 0 the test compares nothing
}

template <int kTenthsA>
double Constant(std::size_t) {
  return kTenthsA / 10.0;
}

}  // namespace

TEST_CASE("damper force error below 0.1 % against CVODE at rtol 1e-12: the Fig. 5 sine") {
  const std::size_t n = static_cast<std::size_t>(std::lround(3.0 / kDt));  // three cycles
  const Motion sine;
  CheckAccuracy("sine 25.4 mm 1 Hz, 0.0 A", sine, n, &Constant<0>);
  CheckAccuracy("sine 25.4 mm 1 Hz, 0.5 A", sine, n, &Constant<5>);
  CheckAccuracy("sine 25.4 mm 1 Hz, 1.0 A", sine, n, &Constant<10>);
  CheckAccuracy("sine 25.4 mm 1 Hz, 1.5 A", sine, n, &Constant<15>);
  CheckAccuracy("sine 25.4 mm 1 Hz, 2.0 A", sine, n, &Constant<20>);
  CheckAccuracy("sine 25.4 mm 1 Hz, 2.5 A", sine, n, &Constant<25>);
}

TEST_CASE("damper force error below 0.1 %: motions and currents it was not tuned on") {
  Motion fast;
  fast.amplitude_mm = 2.0, fast.frequency_hz = 8.0;
  CheckAccuracy("sine 2 mm 8 Hz, 1.0 A", fast, 2000, &Constant<10>);

  const std::size_t n = 8000;  // 4 s
  const std::vector<double> x = rths::signal::Blwn(30.0, 2.0, kDt, n + 1, 11, 1.0);
  Motion blwn;
  blwn.x_mm = &x;
  CheckAccuracy("BLWN 0-30 Hz 2 mm RMS, 0.0 A", blwn, n, &Constant<0>);
  CheckAccuracy("BLWN 0-30 Hz 2 mm RMS, 2.5 A", blwn, n, &Constant<25>);
  // Current pulses 0 <-> 2.5 A every 10 ms (steps of 4 A/ms in the coefficients).
  CheckAccuracy("BLWN, pulsed current", blwn, n, [](std::size_t k) { return (k / 20) % 2 ? 2.5 : 0.0; });
  CheckAccuracy("sine, pulsed current", Motion{}, 6000,
                [](std::size_t k) { return (k / 50) % 2 ? 2.5 : 0.0; });
}

TEST_CASE("a re-answered step is bit-identical, whatever ran in between") {
  for (OdeMethod method : {OdeMethod::kErk, OdeMethod::kBdf}) {
    Motion sine;
    MrDamperStepper stepper(MrDamperParams::Table3(), &MotionAt, &sine, 1e-8, method);
    MrDamperState first{0.3, 12.0}, again = first;
    stepper.Advance(0.1, 0.1 + kDt, 1.0, &first);
    for (int j = 0; j < 50; ++j) {  // other steps, other states, other currents
      MrDamperState other{0.01 * j, 40.0 - j};
      stepper.Advance(0.013 * j, 0.013 * j + kDt, 0.05 * j, &other);
    }
    stepper.Advance(0.1, 0.1 + kDt, 1.0, &again);
    CHECK(first.y_mm == again.y_mm);
    CHECK(first.z_mm == again.z_mm);
    CHECK(first.z_mm != 12.0);  // it moved
  }
}
