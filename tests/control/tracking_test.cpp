// Offline tracking check (docs/experiments.md E3; docs/models.md sections 2 and 9): the proposed
// feedforward (Eqs. 19-22) driving the linear servo model (Eq. 30, ZOH at 2 kHz), scored by
// Eq. 31 on 60 s BLWN records. Expected values are the independent computations quoted in
// docs/experiments.md E3 and a closed-form lag estimate, not outputs of this code.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "control/feedforward.h"
#include "models/servo_linear.h"
#include "scenario/scenario.h"
#include "signal/blwn.h"
#include "signal/metrics.h"

namespace ctl = rths::control;
namespace sig = rths::signal;
namespace mdl = rths::models;
using rths::models::ServoModel3;

namespace {

constexpr double kDt = 0.0005;          // 2 kHz
constexpr std::size_t kSteps = 120000;  // 60 s kept (docs/models.md section 9)
constexpr double kDiscardS = 2.0;       // first 2 s discarded
constexpr std::uint64_t kSeed = 1;      // the scenario default (signal::SignalSpec::seed)
constexpr std::size_t kSettle = 200;    // 0.1 s: the start-up transient (see below)

ServoModel3 AvgModel() {  // Eq. 30
  ServoModel3 m;
  m.K = 1.600e7;
  m.p = 151.7;
  m.b = 250.4;
  m.c = 1.061e5;
  m.name = "avg";
  return m;
}

enum class Mode { kNone, kFeedforward, kHalfStepAhead, kExtraDelay, kCentral };

struct Score {
  double full = 0.0;    // Eq. 31 over the whole record [%]
  double steady = 0.0;  // Eq. 31 from step kSettle on [%]
};

// One predefined-displacement run. Step indices: at step i the controller has r_i (and the past
// r for Eqs. 20-22) and computes u_i; the measurement y_i = C z_i depends on u_0 .. u_{i-1} only;
// then u_i is held over [t_i, t_{i+1}). kExtraDelay holds u_{i-1} instead (an off-by-one).
Score Track(const std::vector<double>& r, Mode mode) {
  const mdl::LinearServo servo = mdl::LinearServo::Make(AvgModel(), kDt);
  mdl::LinearServoState state;
  const ctl::FeedforwardCoefficients a = ctl::MakeFeedforwardCoefficients(AvgModel());
  ctl::ExtrapolationState past;
  const ctl::DerivativeRecords central =
      mode == Mode::kCentral ? ctl::CentralDerivatives(r, kDt) : ctl::DerivativeRecords{};
  sig::RmsErrorAccumulator full, steady;
  double u_prev = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const ctl::Derivatives d = ctl::StepDerivatives(&past, r[i], kDt);  // Eqs. 20-22
    double u = 0.0;
    switch (mode) {
      case Mode::kNone: u = r[i]; break;
      case Mode::kFeedforward:
      case Mode::kExtraDelay: u = ctl::FeedforwardCommand(a, d, false, kDt); break;
      case Mode::kHalfStepAhead: u = ctl::FeedforwardCommand(a, d, true, kDt); break;
      case Mode::kCentral: u = ctl::FeedforwardCommand(a, central.At(r, i), false, kDt); break;
    }
    const double y = mdl::Output(servo, state);
    full.Add(r[i], y);
    if (i >= kSettle) steady.Add(r[i], y);
    mdl::Step(servo, &state, mode == Mode::kExtraDelay ? u_prev : u);
    u_prev = u;
  }
  return {full.Percent(), steady.Percent()};
}

// Eq. 31 of a pure delay tau on r, to first order: |1 - e^{-j w tau}| ~ w tau, so
// e ~ tau rms(r') / rms(r) x 100 % (r' by central differences of the record).
double LagErrorPercent(const std::vector<double>& r, double tau) {
  double s1 = 0.0, s0 = 0.0;
  for (std::size_t i = 1; i + 1 < r.size(); ++i) {
    const double v = (r[i + 1] - r[i - 1]) / (2.0 * kDt);
    s1 += v * v;
    s0 += r[i] * r[i];
  }
  return tau * std::sqrt(s1 / s0) * 100.0;
}

void Band(double band_hz, double rms, double none_ref, double ff_max) {
  const auto r = sig::Blwn(band_hz, rms, kDt, kSteps, kSeed, kDiscardS);
  const Score none = Track(r, Mode::kNone), ff = Track(r, Mode::kFeedforward),
              half = Track(r, Mode::kHalfStepAhead), late = Track(r, Mode::kExtraDelay),
              cen = Track(r, Mode::kCentral);
  const double lag = LagErrorPercent(r, kDt / 2);  // the ZOH's half sample
  std::printf("0-%g Hz BLWN, RMS %g mm, seed %llu, r_0 = %.3f mm; Eq. 31 [%%] whole record / after 0.1 s:\n",
              band_hz, rms, static_cast<unsigned long long>(kSeed), r[0]);
  std::printf("  %-36s %7.3f  %7.3f\n", "none (u = r)", none.full, none.steady);
  std::printf("  %-36s %7.3f  %7.3f\n", "FF avg, Eq. 19 with Eqs. 20-22", ff.full, ff.steady);
  std::printf("  %-36s %7.3f  %7.3f\n", "FF avg, half step ahead", half.full, half.steady);
  std::printf("  %-36s %7.3f  %7.3f\n", "FF avg, one extra step of delay", late.full, late.steady);
  std::printf("  %-36s %7.3f  %7.3f\n", "FF avg, offline central differences", cen.full, cen.steady);
  std::printf("  %-36s %7s  %7.3f\n", "estimate: pure lag of dt/2", "", lag);

  // docs/experiments.md E3: None on the ZOH Eq. 30 model is 16.5 / 46.1 % (flat band spectrum).
  CHECK(none.full == doctest::Approx(none_ref).epsilon(2.0 / none_ref));
  // Required (docs/experiments.md E3): < 1 % / < 2.5 %; independent computations 0.45-0.7 % / 1.3-1.9 %.
  CHECK(ff.full < ff_max);
  // One extra step of delay must be clearly worse (docs/experiments.md E3: about 1.4 / 4.0 %).
  CHECK(late.full > 2.0 * ff.full);

  // After the start-up transient the record is tracked up to the hold's half-sample lag:
  // exact derivatives (central) leave just that lag; Eqs. 20-22 nearly so; half a step ahead
  // removes it; one step more triples it.
  CHECK(cen.steady == doctest::Approx(lag).epsilon(0.05));
  CHECK(ff.steady == doctest::Approx(lag).epsilon(0.10));
  CHECK(half.steady < 0.25 * lag);
  CHECK(late.steady == doctest::Approx(3.0 * lag).epsilon(0.10));
}

}  // namespace

// The record starts mid-motion (r_0 != 0 after the 2 s discard) while the plant starts at rest,
// so every controller pays a start-up transient of roughly 0.4 % x |r_0| / RMS (60 s record)
// on top of its steady error: that is what moves the whole-record FF figure with the seed.
TEST_CASE("tracking: proposed feedforward on the average plant, 0-5 Hz, RMS 2.78 mm") {
  Band(5.0, 2.78, 16.5, 1.0);
}

TEST_CASE("tracking: proposed feedforward on the average plant, 0-15 Hz, RMS 0.595 mm") {
  Band(15.0, 0.595, 46.1, 2.5);
}
