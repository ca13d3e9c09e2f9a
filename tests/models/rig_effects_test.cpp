// The effect library's blocks (lib/models/rig_effects.h): each one's signature on simple inputs.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "alloc_counter.h"
#include "core/error.h"
#include "models/rig_effects.h"
#include "models/servo_flow_limit.h"

using namespace rths;
using namespace rths::models;

namespace {
constexpr double kDt = 0.0005;
}

TEST_CASE("an empty effect set is the identity") {
  EffectSet e;
  CHECK(e.Empty());
  DisplacementEffects d(e, kDt);
  ForceEffects f(e, kDt);
  CHECK(d.PreIsIdentity());
  for (int k = 0; k < 100; ++k) {
    const double u = std::sin(0.1 * k);
    CHECK(d.Pre(u) == u);
    CHECK(d.Post(u, 3.0) == u);
    CHECK(f.Current(u) == u);
    CHECK(f.Force(u) == u);
  }
}

TEST_CASE("pure_delay shifts the command by tau, with linear interpolation") {
  EffectSet e;
  e.pure_delay = PureDelay{1.25};  // 2.5 samples
  DisplacementEffects d(e, kDt);
  CHECK_FALSE(d.PreIsIdentity());
  // A ramp u_k = k: delayed by 2.5 samples -> k - 2.5 once the line is full.
  for (int k = 0; k < 20; ++k) {
    const double out = d.Pre(k);
    if (k >= 3) CHECK(out == doctest::Approx(k - 2.5).epsilon(1e-12));
    if (k < 2) CHECK(out == 0.0);
  }
}

TEST_CASE("gain_error scales the command") {
  EffectSet e;
  e.gain_error = GainError{1.1};
  DisplacementEffects d(e, kDt);
  CHECK(d.Pre(2.0) == doctest::Approx(2.2));
}

TEST_CASE("oil_column_resonance: unity at DC, rings at f_hz") {
  EffectSet e;
  e.oil_column_resonance = OilColumnResonance{50.0, 0.05};
  DisplacementEffects d(e, kDt);
  // Step response: overshoot ~ exp(-pi zeta / sqrt(1 - zeta^2)) = 0.855, settles at 1.
  double peak = 0.0, last = 0.0;
  int first_peak = -1;
  double prev = 0.0;
  for (int k = 0; k < 20000; ++k) {
    last = d.Post(1.0, 0.0);
    if (first_peak < 0 && k > 0 && last < prev) first_peak = k - 1;
    prev = last;
    peak = std::max(peak, last);
  }
  CHECK(last == doctest::Approx(1.0).epsilon(1e-9));
  CHECK(peak - 1.0 == doctest::Approx(0.855).epsilon(0.01));
  // First peak at half the damped period: 1 / (2 f_d) = 10.0 ms = 20 samples (+-1, ZOH).
  CHECK(first_peak >= 19);
  CHECK(first_peak <= 21);
}

TEST_CASE("servovalve_saturation bounds the output's rate") {
  EffectSet e;
  e.servovalve_saturation = ServovalveSaturation{100.0};  // 0.05 mm per step
  DisplacementEffects d(e, kDt);
  double prev = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double y = d.Post(5.0 * std::sin(2 * M_PI * 10 * k * kDt), 0.0);  // 314 mm/s peak
    CHECK(std::abs(y - prev) <= 0.05 + 1e-12);
    prev = y;
  }
}

TEST_CASE("load_coupling: y = x - c f") {
  EffectSet e;
  e.load_coupling = LoadCoupling{0.01};
  DisplacementEffects d(e, kDt);
  CHECK(d.Post(1.0, 20.0) == doctest::Approx(0.8));
}

TEST_CASE("coulomb_friction loses displacement against the motion") {
  EffectSet e;
  e.coulomb_friction = CoulombFriction{0.1, 0.5};
  DisplacementEffects d(e, kDt);
  double y = 0.0;
  for (int k = 1; k <= 100; ++k) y = d.Post(0.01 * k, 0.0);  // 20 mm/s upwards
  CHECK(y == doctest::Approx(1.0 - 0.1).epsilon(1e-6));
  for (int k = 99; k >= 50; --k) y = d.Post(0.01 * k, 0.0);  // downwards
  CHECK(y == doctest::Approx(0.5 + 0.1).epsilon(1e-6));
}

TEST_CASE("backlash: lost motion of the gap at a reversal") {
  EffectSet e;
  e.backlash = Backlash{0.2};
  DisplacementEffects d(e, kDt);
  double y = 0.0;
  for (int k = 1; k <= 100; ++k) y = d.Post(0.01 * k, 0.0);
  CHECK(y == doctest::Approx(0.9));  // trails by gap / 2
  // Reverse by 0.15 mm (< gap): the output does not move.
  for (int k = 99; k >= 85; --k) CHECK(d.Post(0.01 * k, 0.0) == doctest::Approx(0.9));
  y = d.Post(0.5, 0.0);
  CHECK(y == doctest::Approx(0.6));
}

namespace {
/// presliding_friction's lost motion z = x - y along a path of inputs, by the block.
double PreslidingLoss(DisplacementEffects* d, double x) { return x - d->Post(x, 0.0); }
}  // namespace

TEST_CASE("presliding_friction: Dahl's law on the output's travel, solved exactly per sample") {
  const double loss = 0.2, travel = 0.1;
  EffectSet e;
  e.presliding_friction = PreslidingFriction{loss, travel};
  // Sliding far one way: the lost motion is the loss.
  DisplacementEffects d(e, kDt);
  for (int k = 1; k <= 400; ++k) PreslidingLoss(&d, 0.01 * k);
  CHECK(PreslidingLoss(&d, 4.0) == doctest::Approx(loss).epsilon(1e-9));
  // After a reversal the output creeps at travel / (travel + 2 loss) of the input's rate ...
  const double y0 = d.Post(4.0, 0.0);
  const double y1 = d.Post(4.0 - 1e-6, 0.0);
  CHECK((y0 - y1) / 1e-6 == doctest::Approx(travel / (travel + 2.0 * loss)).epsilon(1e-4));
  // ... and the exact per-sample solution does not depend on how the travel is sampled: one big
  // step against 1000 small ones, from the same state (the closed form, Newton on W + ln W = q).
  DisplacementEffects coarse = d, fine = d;
  const double zc = PreslidingLoss(&coarse, 4.0 - 0.3);
  double zf = 0.0;
  for (int k = 1; k <= 1000; ++k) zf = PreslidingLoss(&fine, 4.0 - 1e-6 - (0.3 - 1e-6) * k / 1000.0);
  CHECK(zc == doctest::Approx(zf).epsilon(1e-9));
  // The implicit law travel ln w + w = const - travel along the reversal's travel (w = loss - s z).
  const double w_start = loss + loss, w_end = loss + zc;  // s = -1 after the reversal
  CHECK(travel * std::log(w_end) + w_end == doctest::Approx(travel * std::log(w_start) + w_start - 0.3).epsilon(1e-6));
  CHECK(zc < 0.0);
  CHECK(zc > -loss);
}

TEST_CASE("presliding_friction with a vanishing travel is backlash of gap 2 loss") {
  EffectSet p, b;
  p.presliding_friction = PreslidingFriction{0.1, 1e-6};
  b.backlash = Backlash{0.2};
  DisplacementEffects dp(p, kDt), db(b, kDt);
  double worst = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double x = 2.0 * std::sin(2.0 * M_PI * 1.3 * k * kDt) + 0.5 * std::sin(2.0 * M_PI * 7.0 * k * kDt);
    worst = std::max(worst, std::abs(dp.Post(x, 0.0) - db.Post(x, 0.0)));
  }
  // The play operator is centred, so the two differ by a constant shift of the gap's half at most.
  CHECK(worst < 1e-4);
}

TEST_CASE("command_dead_band: the actuator gets no command within width/2 of its output") {
  EffectSet e;
  e.command_dead_band = CommandDeadBand{0.4};
  DisplacementEffects d(e, kDt);
  CHECK_FALSE(d.PreIsIdentity());
  d.Post(1.0, 0.0);               // the actuator output x_k = 1 mm
  CHECK(d.Pre(1.15) == 1.0);      // inside the band: hold
  CHECK(d.Pre(0.85) == 1.0);
  CHECK(d.Pre(1.5) == doctest::Approx(1.3));   // beyond: the error less the half width
  CHECK(d.Pre(0.0) == doctest::Approx(0.2));
}

TEST_CASE("supply_ripple adds the library's harmonic shape at t_k = k dt, from Reset") {
  EffectSet e;
  e.supply_ripple = SupplyRipple{150.0, 0.02};
  DisplacementEffects d(e, kDt);
  CHECK(d.PreIsIdentity());  // it acts on the output only
  auto expected = [](int k) {
    const double t = k * kDt;
    return 0.02 * (std::sin(2 * M_PI * 150.0 * t) + 0.5 * std::sin(2 * M_PI * 300.0 * t + 1.0) +
                   0.25 * std::sin(2 * M_PI * 450.0 * t + 2.0));
  };
  for (int k = 0; k < 50; ++k) CHECK(d.Post(1.0, 0.0) == doctest::Approx(1.0 + expected(k)).epsilon(1e-12));
  d.Reset();
  CHECK(d.Post(0.0, 0.0) == doctest::Approx(expected(0)).epsilon(1e-12));  // sin(0) + 0.5 sin 1 + 0.25 sin 2
  CHECK(expected(0) != 0.0);
  // At 400 Hz the third harmonic (1200 Hz) is above the Nyquist frequency (1 kHz): left out.
  EffectSet high;
  high.supply_ripple = SupplyRipple{400.0, 0.02};
  DisplacementEffects dh(high, kDt);
  for (int k = 0; k < 20; ++k) {
    const double t = k * kDt;
    CHECK(dh.Post(0.0, 0.0) ==
          doctest::Approx(0.02 * (std::sin(2 * M_PI * 400.0 * t) + 0.5 * std::sin(2 * M_PI * 800.0 * t + 1.0))).epsilon(1e-12));
  }
  EffectSet bad;
  bad.supply_ripple = SupplyRipple{1000.0, 0.01};  // at the Nyquist frequency 0.5 / dt
  CHECK_THROWS_AS(DisplacementEffects(bad, kDt), Error);
}

TEST_CASE("current_lag is a first-order lag; damper_scale scales") {
  EffectSet e;
  e.current_lag = CurrentLag{10.0};
  e.damper_scale = DamperScale{0.8};
  ForceEffects f(e, kDt);
  double i = 0.0;
  for (int k = 0; k < 20; ++k) i = f.Current(2.5);  // 10 ms = tau
  CHECK(i == doctest::Approx(2.5 * (1 - std::exp(-1.0))).epsilon(1e-9));
  CHECK(f.Force(10.0) == doctest::Approx(8.0));
  f.Reset(1.0);
  CHECK(f.Current(1.0) == doctest::Approx(1.0));
}

TEST_CASE("bad parameters name the effect, the key and the range") {
  EffectSet e;
  e.backlash = Backlash{-1.0};
  try {
    e.Validate(kDt, "s.toml");
    FAIL("no error");
  } catch (const Error& err) {
    const std::string msg = err.what();
    CHECK(msg.find("s.toml") != std::string::npos);
    CHECK(msg.find("backlash.gap_mm") != std::string::npos);
    CHECK(msg.find("[0, 10]") != std::string::npos);
  }
  EffectSet o;
  o.oil_column_resonance = OilColumnResonance{1000.0, 0.1};  // above 0.45 / dt = 900 Hz
  CHECK_THROWS_AS(DisplacementEffects(o, kDt), Error);
}

TEST_CASE("the per-step calls allocate nothing") {
  EffectSet e;
  e.pure_delay = PureDelay{3.3};
  e.gain_error = GainError{1.05};
  e.oil_column_resonance = OilColumnResonance{40.0, 0.1};
  e.servovalve_saturation = ServovalveSaturation{200.0};
  e.load_coupling = LoadCoupling{0.001};
  e.coulomb_friction = CoulombFriction{0.02, 0.5};
  e.backlash = Backlash{0.05};
  e.presliding_friction = PreslidingFriction{0.03, 0.05};
  e.command_dead_band = CommandDeadBand{0.02};
  e.supply_ripple = SupplyRipple{120.0, 0.01};
  e.current_lag = CurrentLag{5.0};
  e.damper_scale = DamperScale{1.2};
  DisplacementEffects d(e, kDt);
  ForceEffects f(e, kDt);
  double acc = 0.0;
  const long before = rths_test::AllocationCount();
  for (int k = 0; k < 1000; ++k) {
    const double u = d.Pre(std::sin(0.01 * k));
    acc += d.Post(u, 1.0) + f.Force(f.Current(1.0));
  }
  CHECK(rths_test::AllocationCount() == before);
  CHECK(std::isfinite(acc));
}

TEST_CASE("ShiftSamples: exact for cubics at any shift, either sign; the record held at its ends") {
  std::vector<double> x(200);
  auto cubic = [](double t) { return 0.3 + 0.2 * t - 0.01 * t * t + 1e-4 * t * t * t; };
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = cubic(static_cast<double>(k));
  for (const double shift_samples : {0.3, 1.0, 2.7, -0.4, -3.25}) {
    const auto y = ShiftSamples(x, shift_samples * kDt, kDt);
    for (std::size_t k = 10; k + 10 < x.size(); ++k)
      CHECK(y[k] == doctest::Approx(cubic(static_cast<double>(k) - shift_samples)).epsilon(1e-12));
  }
  const auto late = ShiftSamples(x, 5.0 * kDt, kDt);
  CHECK(late[0] == x[0]);  // before the record: its first sample
  CHECK(ShiftSamples(x, 0.0, kDt) == x);
}

TEST_CASE("MeasurementEffects: load_cell_inertia adds m a; channel_skew delays the force, or the displacement if < 0") {
  EffectSet e;
  e.load_cell_inertia = LoadCellInertia{50.0};
  MeasurementEffects m(e, kDt);
  double y = 0, f = 0;
  m.Measure(1.0, 2e4, 3.0, &y, &f);
  CHECK(y == 1.0);
  CHECK(f == doctest::Approx(3.0 + 50.0 * 2e4 * 1e-6));
  // A skew of 1.6 samples: the causal delay line agrees with the offline shift inside the record.
  for (const double skew_samples : {1.6, 0.4, -2.3}) {
    EffectSet s;
    s.channel_skew = ChannelSkew{skew_samples * kDt * 1e3};
    MeasurementEffects ms(s, kDt);
    std::vector<double> sig(400), ym(400), fm(400);
    for (std::size_t k = 0; k < sig.size(); ++k) {
      sig[k] = std::sin(2.0 * M_PI * 15.0 * static_cast<double>(k) * kDt);  // 15 Hz at 2 kHz
      ms.Measure(sig[k], 0.0, sig[k], &ym[k], &fm[k]);
    }
    const auto shifted = ShiftSamples(sig, std::abs(skew_samples) * kDt, kDt);
    const auto& delayed = skew_samples > 0 ? fm : ym;
    const auto& other = skew_samples > 0 ? ym : fm;
    for (std::size_t k = 20; k + 3 < sig.size(); ++k) {  // ShiftSamples holds the record's end past it
      CHECK(std::abs(delayed[k] - shifted[k]) < 1e-4);
      CHECK(other[k] == sig[k]);
    }
  }
  const auto before = rths_test::AllocationCount();
  m.Measure(0.5, 1.0, 1.0, &y, &f);
  CHECK(rths_test::AllocationCount() == before);
}

TEST_CASE("FlowLimitedServo: the linear model below its limit; the piston held at vmax while the loop winds up") {
  const auto linear = LinearServo::Make(ServoPreset("avg"), kDt);
  const auto free = FlowLimitedServo::Make(ServoPreset("avg"), 1e9, kDt);
  // Below the limit: the exact ZOH (both paths of Step: the linear one and RK4 checked apart).
  LinearServoState z;
  FlowLimitedServoState s;
  double worst = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double u = 5.0 * std::sin(2.0 * M_PI * 3.0 * k * kDt) + 2.0 * std::sin(2.0 * M_PI * 17.0 * k * kDt);
    Step(linear, &z, u);
    Step(free, &s, u);
    worst = std::max(worst, std::abs(s.x - Output(linear, z)));
  }
  CHECK(worst < 1e-9);
  // The RK4 path (taken near the limit): a limit just above the motion's fastest velocity never
  // acts, but sends the steps near the peaks through RK4; they agree with the exact ZOH too.
  double vfast = 0.0;
  {
    LinearServoState zz;
    for (int k = 0; k < 4000; ++k) {
      Step(linear, &zz, 5.0 * std::sin(2.0 * M_PI * 3.0 * k * kDt) + 2.0 * std::sin(2.0 * M_PI * 17.0 * k * kDt));
      vfast = std::max(vfast, std::abs(zz.z(1)));
    }
  }
  const auto near = FlowLimitedServo::Make(ServoPreset("avg"), 1.01 * vfast, kDt);
  LinearServoState z2;
  FlowLimitedServoState s2;
  worst = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double u = 5.0 * std::sin(2.0 * M_PI * 3.0 * k * kDt) + 2.0 * std::sin(2.0 * M_PI * 17.0 * k * kDt);
    Step(linear, &z2, u);
    Step(near, &s2, u);
    worst = std::max(worst, std::abs(s2.x - Output(linear, z2)));
  }
  CHECK(worst < 2e-8);  // mm, on a 7 mm motion: 4 RK4 substeps per step (kFlowLimitSubsteps)
  // At the limit: a step command of 20 mm with vmax 100 mm/s.
  const auto lim = FlowLimitedServo::Make(ServoPreset("avg"), 100.0, kDt);
  FlowLimitedServoState q;
  double vpeak = 0.0, xvpeak = 0.0, xmax = 0.0;
  for (int k = 0; k < 2000; ++k) {
    Step(lim, &q, 20.0);
    vpeak = std::max(vpeak, Velocity(lim, q));
    xvpeak = std::max(xvpeak, q.xv);
    xmax = std::max(xmax, q.x);
  }
  CHECK(vpeak <= 100.0);
  CHECK(vpeak > 99.0);
  CHECK(xvpeak > 150.0);   // the loop's velocity state winds up beyond the limit
  CHECK(xmax > 20.0 * linear.DcGain() * 1.01);  // and the piston overshoots when it lets go
  CHECK(q.x == doctest::Approx(20.0 * linear.DcGain()).epsilon(1e-3));
  // The effect library's switch: 0 or 1 only.
  EffectSet e;
  e.servovalve_saturation = ServovalveSaturation{200.0, 0.5};
  CHECK_THROWS_AS(e.Validate(kDt, "plant"), rths::Error);
  e.servovalve_saturation->in_loop = 1.0;
  CHECK_NOTHROW(e.Validate(kDt, "plant"));
}
