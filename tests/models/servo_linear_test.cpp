// Linear servohydraulic model (Eqs. 28-30): ZOH against closed forms, DC gains, time lags.
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include <doctest/doctest.h>

#include "core/error.h"
#include "models/servo_linear.h"

using rths::models::LinearServo;
using rths::models::LinearServoState;
using rths::models::ServoModel3;

namespace {

constexpr double kDt = 0.0005;
const ServoModel3 kModel00{1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};  // Eq. 28
const ServoModel3 kModel25{1.613e7, 134.2, 324.6, 1.211e5, "2.5A"};  // Eq. 29
const ServoModel3 kModelAvg{1.600e7, 151.7, 250.4, 1.061e5, "avg"};  // Eq. 30

// Continuous unit-step response of K / ((s + p)(s^2 + b s + c)) and its derivative, by partial
// fractions over the poles {0, -p, -b/2 +- j wd}: y(t) = sum_i K e^{s_i t} / prod_{j!=i}(s_i -
// s_j).
struct Analytic {
  std::array<std::complex<double>, 4> pole, residue;
  explicit Analytic(const ServoModel3& m) {
    const double wd = std::sqrt(m.c - m.b * m.b / 4.0);
    pole = {0.0, -m.p, {-m.b / 2, wd}, {-m.b / 2, -wd}};
    for (int i = 0; i < 4; ++i) {
      std::complex<double> den = 1.0;
      for (int j = 0; j < 4; ++j)
        if (j != i) den *= pole[i] - pole[j];
      residue[i] = m.K / den;
    }
  }
  double y(double t) const {
    std::complex<double> sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += residue[i] * std::exp(pole[i] * t);
    return sum.real();
  }
  double ydot(double t) const {
    std::complex<double> sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += residue[i] * pole[i] * std::exp(pole[i] * t);
    return sum.real();
  }
};

}  // namespace

TEST_CASE("realisation is the phase-variable form of G") {
  const LinearServo s = LinearServo::Make(kModelAvg, kDt);
  CHECK(s.A(0, 1) == 1.0);
  CHECK(s.A(1, 2) == 1.0);
  CHECK(s.A(2, 0) == doctest::Approx(-1.60954e7).epsilon(1e-5));  // -d0 (docs/models.md table)
  CHECK(s.A(2, 1) == doctest::Approx(-144085.7).epsilon(1e-6));   // -d1
  CHECK(s.A(2, 2) == doctest::Approx(-402.1).epsilon(1e-9));      // -d2
  CHECK(s.B(2) == 1.600e7);
  CHECK(s.C(0) == 1.0);
}

TEST_CASE("ZOH step response equals the continuous step response at the samples") {
  for (const ServoModel3& m : {kModel00, kModel25, kModelAvg}) {
    CAPTURE(m.name);
    const LinearServo s = LinearServo::Make(m, kDt);
    const Analytic a(m);
    LinearServoState st;
    double max_err = 0.0, max_verr = 0.0;
    for (int k = 0; k <= 400; ++k) {  // 0.2 s: through the transient to steady state
      max_err = std::max(max_err, std::abs(Output(s, st) - a.y(k * kDt)));
      max_verr = std::max(max_verr, std::abs(OutputVelocity(s, st) - a.ydot(k * kDt)));
      Step(s, &st, 1.0);
    }
    CHECK(max_err < 1e-10);  // mm per mm of step
    CHECK(max_verr < 1e-7);  // mm/s per mm of step (peak velocity is about 200 mm/s)
    CHECK(Output(s, st) == doctest::Approx(s.DcGain()).epsilon(1e-6));
  }
}

TEST_CASE("time index: y_k depends on u up to u_{k-1} only") {
  const LinearServo s = LinearServo::Make(kModelAvg, kDt);
  const Analytic a(kModelAvg);
  LinearServoState st;
  Step(s, &st, 1.0);  // u_0 = 1 (a one-sample pulse)
  CHECK(Output(s, LinearServoState{}) == 0.0);
  CHECK(Output(s, st) == doctest::Approx(a.y(kDt)).epsilon(1e-9));
  Step(s, &st, 0.0);  // pulse response at t = 2 dt: step(2dt) - step(dt)
  CHECK(Output(s, st) == doctest::Approx(a.y(2 * kDt) - a.y(kDt)).epsilon(1e-9));
}

TEST_CASE("DC gains and time lags of Eqs. 28-30 (docs/models.md section 1)") {
  struct Row {
    ServoModel3 model;
    double dc_gain, dc_lag_ms;
  };
  for (const Row& r : {Row{kModel00, 0.99685, 7.85}, Row{kModel25, 0.99252, 10.13},
                       Row{kModelAvg, 0.99407, 8.95}}) {
    CAPTURE(r.model.name);
    const LinearServo s = LinearServo::Make(r.model, kDt);
    CHECK(s.DcGain() == doctest::Approx(r.dc_gain).epsilon(1e-5));
    CHECK(std::abs(FrequencyResponse(s, 1e-6, false) - r.dc_gain) < 1e-5);
    CHECK(std::abs(FrequencyResponse(s, 1e-6, true) - r.dc_gain) < 1e-5);
    // At 1 Hz the lag is still the DC lag d1/d0; the ZOH adds half a sample (0.25 ms).
    const double lag_c = TimeLagS(s, 1.0, false) * 1e3, lag_d = TimeLagS(s, 1.0, true) * 1e3;
    MESSAGE(r.model.name << ": DC gain " << s.DcGain() << ", lag at 1 Hz " << lag_c
                         << " ms continuous, " << lag_d << " ms ZOH");
    CHECK(std::abs(lag_c - r.dc_lag_ms) < 0.05);
    CHECK(std::abs(lag_d - (r.dc_lag_ms + 0.25)) < 0.05);
  }
}

TEST_CASE("ZOH response: half-sample delay of the continuous one at low frequency") {
  const LinearServo s = LinearServo::Make(kModelAvg, kDt);
  for (double f : {0.5, 2.0, 5.0, 10.0}) {
    CAPTURE(f);
    const double w = 2 * std::numbers::pi * f;
    const std::complex<double> hc = FrequencyResponse(s, f, false);
    const std::complex<double> hd = FrequencyResponse(s, f, true);
    const std::complex<double> delayed = hc * std::exp(std::complex<double>(0, -w * kDt / 2));
    CHECK(std::abs(hd - delayed) < 1e-3 * std::abs(hc));
  }
  // The phase passes -180 deg (3-pole model): the unwrapped lag keeps growing past it.
  CHECK(TimeLagS(s, 80.0, false) > 0.5 / 80.0);
}

TEST_CASE("Make rejects bad models") {
  CHECK_THROWS_AS(LinearServo::Make(ServoModel3{-1, 1, 1, 1, "x"}, kDt), rths::Error);
  CHECK_THROWS_AS(LinearServo::Make(ServoModel3{1, 1, 0, 1, "x"}, kDt), rths::Error);
  CHECK_THROWS_AS(LinearServo::Make(kModelAvg, 0.0), rths::Error);
  CHECK_THROWS_AS(LinearServo::Make(kModelAvg, NAN), rths::Error);
}
