// The RTHS benchmark's control plant (Silva et al. 2020; lib/models/benchmark_plant.h): order, DC
// gain, poles against an independently expanded denominator, low-frequency lag, ZOH step
// response, and the seeded parameter uncertainty.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/Core>
#include <unsupported/Eigen/Polynomials>

#include "core/error.h"
#include "models/benchmark_plant.h"

using rths::models::BenchmarkPlant;
using rths::models::BenchmarkPlantParams;
using rths::models::BenchmarkPlantState;

namespace {

constexpr double kDt = 1.0 / 4096.0;  // the benchmark's loop rate

// The denominator of Gp times m_e, expanded by hand (ascending powers of s):
// (s^2 + b1 s + b2)(q3 s^3 + q2 s^2 + q1 s + q0) + a1b0 with
// q3 = m_e, q2 = c_e + a3 m_e, q1 = k_e + a3 c_e + a2, q0 = a3 k_e.
Eigen::VectorXd HandDenominator(const BenchmarkPlantParams& p) {
  const double ce = 2.0 * p.zeta_e * std::sqrt(p.m_e_kg * p.k_e_N_per_m);
  const double q3 = p.m_e_kg, q2 = ce + p.a3 * p.m_e_kg, q1 = p.k_e_N_per_m + p.a3 * ce + p.a2,
               q0 = p.a3 * p.k_e_N_per_m;
  Eigen::VectorXd d(6);
  d << p.b2 * q0 + p.a1b0, p.b1 * q0 + p.b2 * q1, q0 + p.b1 * q1 + p.b2 * q2, q1 + p.b1 * q2 + p.b2 * q3,
      q2 + p.b1 * q3, q3;
  return d;
}

std::vector<std::complex<double>> HandPoles(const BenchmarkPlantParams& p) {
  Eigen::PolynomialSolver<double, Eigen::Dynamic> solver;
  solver.compute(HandDenominator(p));
  const Eigen::VectorXcd r = solver.roots();
  std::vector<std::complex<double>> out(r.data(), r.data() + r.size());
  return out;
}

// Distance from `z` to the nearest of `set`.
double Nearest(std::complex<double> z, const std::vector<std::complex<double>>& set) {
  double best = INFINITY;
  for (const auto& s : set) best = std::min(best, std::abs(z - s));
  return best;
}

}  // namespace

TEST_CASE("nominal plant: fifth order, DC gain 1.0075") {
  const BenchmarkPlant m = BenchmarkPlant::Make({}, kDt);
  CHECK(m.Order() == 5);
  CHECK(m.poly.den.size() == 6);
  CHECK(m.poly.num.size() == 1);
  // gain a1b0 / (b2 a3 k_e + a1b0), the "about 1.0075".
  const BenchmarkPlantParams p;
  const double closed_form = p.gain * p.a1b0 / (p.b2 * p.a3 * p.k_e_N_per_m + p.a1b0);
  CHECK(m.DcGain() == doctest::Approx(closed_form).epsilon(1e-12));
  CHECK(m.DcGain() == doctest::Approx(1.0075).epsilon(1e-4));
  CHECK(std::abs(FrequencyResponse(m, 1e-4, false)) == doctest::Approx(m.DcGain()).epsilon(1e-8));
  // The denominator (divided by m_e) is the hand-expanded one.
  const Eigen::VectorXd hand = HandDenominator(p) / p.m_e_kg;
  for (int i = 0; i < 6; ++i) CHECK(m.poly.den(i) == doctest::Approx(hand(i)).epsilon(1e-12));
}

TEST_CASE("poles: the roots of the hand-expanded denominator, all stable") {
  for (const BenchmarkPlantParams& p :
       {BenchmarkPlantParams{}, rths::models::PerturbedBenchmarkParams({}, 7), rths::models::PerturbedBenchmarkParams({}, 8)}) {
    const BenchmarkPlant m = BenchmarkPlant::Make(p, kDt);
    const auto poles = m.Poles();
    const auto hand = HandPoles(p);
    REQUIRE(poles.size() == 5);
    REQUIRE(hand.size() == 5);
    for (const auto& z : poles) {
      CAPTURE(z);
      CHECK(z.real() < 0.0);
      CHECK(Nearest(z, hand) < 1e-7 * std::abs(z));
    }
    for (const auto& z : hand) CHECK(Nearest(z, poles) < 1e-7 * std::abs(z));
    // sorted by magnitude
    for (std::size_t i = 1; i < poles.size(); ++i) CHECK(std::abs(poles[i - 1]) <= std::abs(poles[i]));
  }
}

TEST_CASE("about 25 ms of lag below 2 Hz") {
  const BenchmarkPlant m = BenchmarkPlant::Make({}, kDt);
  for (double f : {0.5, 1.0, 1.5, 2.0}) {
    CAPTURE(f);
    const double lag = TimeLagS(m, f, false);
    CHECK(lag > 0.023);
    CHECK(lag < 0.027);
    // The ZOH model adds half a step of hold lag.
    CHECK(TimeLagS(m, f, true) == doctest::Approx(lag + kDt / 2).epsilon(2e-3));
  }
  CHECK_THROWS_AS(TimeLagS(m, 0.0, false), rths::Error);
}

TEST_CASE("ZOH step response converges to the DC gain; mm edge scales") {
  const BenchmarkPlant m = BenchmarkPlant::Make({}, kDt);
  BenchmarkPlantState s;
  CHECK(Output(m, s) == 0.0);
  double y = 0.0, peak = 0.0;
  const int n = 4 * 4096;  // 4 s
  for (int k = 0; k < n; ++k) {
    y = Step(m, &s, 1.0);
    peak = std::max(peak, y);
  }
  CHECK(y == doctest::Approx(m.DcGain()).epsilon(1e-6));
  CHECK(Output(m, s) == y);
  CHECK(peak < 1.5);  // a servo loop, not an oscillator
  // Step() is strictly proper: the first step's output depends on u_0 through Gamma only.
  BenchmarkPlantState s1, s2;
  const double y1 = Step(m, &s1, 2e-3);   // 2 mm in metres
  const double y2 = StepMm(m, &s2, 2.0);  // 2 mm
  CHECK(y2 == doctest::Approx(1e3 * y1).epsilon(1e-12));
}

TEST_CASE("discrete and continuous frequency responses agree well below Nyquist") {
  const BenchmarkPlant m = BenchmarkPlant::Make({}, kDt);
  for (double f : {0.1, 1.0, 5.0, 20.0}) {
    CAPTURE(f);
    const auto hc = FrequencyResponse(m, f, false);
    const auto hd = FrequencyResponse(m, f, true);
    CHECK(std::abs(hd) == doctest::Approx(std::abs(hc)).epsilon(1e-3 + 1e-4 * f));
  }
}

TEST_CASE("uncertainty: reproducible per seed, the stated spreads over many draws") {
  const BenchmarkPlantParams nominal;
  const BenchmarkPlantParams a = rths::models::PerturbedBenchmarkParams(nominal, 42);
  const BenchmarkPlantParams b = rths::models::PerturbedBenchmarkParams(nominal, 42);
  const BenchmarkPlantParams c = rths::models::PerturbedBenchmarkParams(nominal, 43);
  CHECK(a == b);
  CHECK(!(a == c));
  // Only b1, b2, a3 and k_e move.
  CHECK(a.gain == nominal.gain);
  CHECK(a.a1b0 == nominal.a1b0);
  CHECK(a.a2 == nominal.a2);
  CHECK(a.m_e_kg == nominal.m_e_kg);
  CHECK(a.zeta_e == nominal.zeta_e);
  CHECK(a.b1 != nominal.b1);

  const int n = 20000;
  struct Moments {
    double sum = 0, sum2 = 0;
    void Add(double v) { sum += v, sum2 += v * v; }
    double Mean(int n) const { return sum / n; }
    double Std(int n) const { return std::sqrt((sum2 - sum * sum / n) / (n - 1)); }
  } b1, b2, a3, ke;
  int unstable = 0;
  for (int i = 0; i < n; ++i) {
    const BenchmarkPlantParams p = rths::models::PerturbedBenchmarkParams(nominal, 1000 + i);
    b1.Add(p.b1), b2.Add(p.b2), a3.Add(p.a3), ke.Add(p.k_e_N_per_m);
    if (i % 20 == 0) {  // a sample of the draws: every one is a stable plant
      try {
        rths::models::ValidateBenchmarkParams(p);
      } catch (const rths::Error&) {
        ++unstable;
      }
    }
  }
  CHECK(unstable == 0);
  // Standard error of the mean sigma / sqrt(n) = 0.7 % of sigma; of the std about 0.5 %.
  CHECK(b1.Mean(n) == doctest::Approx(425.0).epsilon(0.05 * 3.3 / 425.0));
  CHECK(b1.Std(n) == doctest::Approx(3.3).epsilon(0.03));
  CHECK(b2.Mean(n) == doctest::Approx(9.9976e4).epsilon(0.05 * 3.3e3 / 9.9976e4));
  CHECK(b2.Std(n) == doctest::Approx(3.3e3).epsilon(0.03));
  CHECK(a3.Mean(n) == doctest::Approx(3.3).epsilon(0.05 * 1.3 / 3.3));
  CHECK(a3.Std(n) == doctest::Approx(1.3).epsilon(0.03));
  CHECK(ke.Mean(n) == doctest::Approx(1.19e6).epsilon(0.05 * 5e4 / 1.19e6));
  CHECK(ke.Std(n) == doctest::Approx(5e4).epsilon(0.03));
}

TEST_CASE("a negative a3 (drawn with probability 0.6 %) still gives a stable plant") {
  BenchmarkPlantParams p;
  p.a3 = -1.0;  // 3.3 sigma below nominal
  CHECK_NOTHROW(rths::models::ValidateBenchmarkParams(p));
  const BenchmarkPlant m = BenchmarkPlant::Make(p, kDt);
  CHECK(m.DcGain() > 1.0);  // b2 a3 k_e < 0: a DC gain above `gain`
}

TEST_CASE("validation names the field and its range") {
  const auto message = [](BenchmarkPlantParams p) -> std::string {
    try {
      rths::models::ValidateBenchmarkParams(p, "bench.toml: plant");
    } catch (const rths::Error& e) {
      return e.what();
    }
    return "";
  };
  BenchmarkPlantParams p;
  p.b1 = -1.0;
  CHECK(message(p).find("bench.toml: plant: b1 [1/s] must be finite and > 0") == 0);
  p = {};
  p.k_e_N_per_m = NAN;
  CHECK(message(p).find("k_e_N_per_m") != std::string::npos);
  p = {};
  p.zeta_e = -0.1;
  CHECK(message(p).find("zeta_e") != std::string::npos);
  p = {};
  p.gain = 0.0;
  CHECK(message(p).find("gain") != std::string::npos);
  p = {};
  p.a1b0 = 1e20;  // a loop gain far beyond stability
  CHECK(message(p).find("unstable") != std::string::npos);
  CHECK_THROWS_AS(BenchmarkPlant::Make({}, 0.0), rths::Error);
  CHECK_THROWS_AS(BenchmarkPlant::Make({}, NAN), rths::Error);
}
