// signal/benchmark_criteria: J1-J9 of the RTHS benchmark (Silva et al. 2020) on synthetic signals
// whose delay and error are known by construction.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.h"
#include "signal/benchmark_criteria.h"

using namespace rths::signal;

namespace {

constexpr double kDt = 1.0 / 4096.0;

/// A sum of sines (1.3, 2.9, 7.1 Hz) with phases, N samples: a target with no period in 50 samples.
std::vector<double> Sines(std::size_t n, double shift_samples = 0.0) {
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = (static_cast<double>(k) - shift_samples) * kDt;
    x[k] = 3.0 * std::sin(2 * std::numbers::pi * 1.3 * t + 0.2) + 1.5 * std::sin(2 * std::numbers::pi * 2.9 * t + 1.1) +
           0.4 * std::sin(2 * std::numbers::pi * 7.1 * t + 2.0);
  }
  return x;
}

/// x delayed by d samples: y[k] = x[k - d], the first d samples repeat x[0].
std::vector<double> Delayed(const std::vector<double>& x, std::size_t d) {
  std::vector<double> y(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) y[k] = x[k >= d ? k - d : 0];
  return y;
}

double SampleStd(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  double s = 0.0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / static_cast<double>(x.size() - 1));
}

double MaxAbs(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

/// Signals for one floor structure: x_m, x_t given; the reference and numerical floor equal x_t.
BenchmarkSignals OneFloor(std::vector<double> x_m, std::vector<double> x_t) {
  BenchmarkSignals s;
  s.dt_s = kDt;
  s.x_r = {x_t};
  s.x_n = {x_t};
  s.x_m = std::move(x_m);
  s.x_t = std::move(x_t);
  return s;
}

std::string ErrorOf(const BenchmarkSignals& s) {
  try {
    BenchmarkCriteriaFrom(s);
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("J1: x_m = x_t delayed by d samples gives J1 = d dt exactly, d = 0 .. 49") {
  const std::vector<double> x_t = Sines(4096);
  for (std::size_t d : {0u, 1u, 7u, 25u, 49u}) {
    CAPTURE(d);
    const BenchmarkCriteria c = BenchmarkCriteriaFrom(OneFloor(Delayed(x_t, d), x_t));
    CHECK(c.lag_samples == static_cast<int>(d));
    CHECK(c.J1_ms == 1e3 * static_cast<double>(d) * kDt);
  }
  // A delay beyond the search (j* <= 50: at most 49 samples) saturates at 49, it does not wrap.
  const BenchmarkCriteria far = BenchmarkCriteriaFrom(OneFloor(Delayed(x_t, 80), x_t));
  CHECK(far.lag_samples == 49);
}

TEST_CASE("J1 on a filtered random signal delayed by 12 samples, with a gain and an offset") {
  // First-order low-pass of a deterministic pseudo-random sequence (an LCG), then delayed by 12
  // samples and scaled by 0.9 plus an offset: the correlation ignores gain and offset.
  std::vector<double> w(8192), x_t(8192);
  std::uint64_t state = 12345;
  for (double& v : w) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    v = static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  }
  double y = 0.0;
  for (std::size_t k = 0; k < w.size(); ++k) x_t[k] = y = 0.97 * y + 0.03 * w[k];
  std::vector<double> x_m = Delayed(x_t, 12);
  for (double& v : x_m) v = 0.9 * v + 0.01;
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(OneFloor(x_m, x_t));
  CHECK(c.lag_samples == 12);
  CHECK(c.J1_ms == doctest::Approx(12e3 / 4096.0).epsilon(1e-15));
}

TEST_CASE("J2, J3: x_m = x_t + e with e of known std and max") {
  const std::size_t n = 5000;
  const std::vector<double> x_t = Sines(n);
  std::vector<double> e(n), x_m(n);
  // e: a square wave of +-0.05 with a single spike of 0.3 at k = 1234 (std and max by hand below).
  for (std::size_t k = 0; k < n; ++k) e[k] = (k / 100) % 2 == 0 ? 0.05 : -0.05;
  e[1234] = 0.3;
  for (std::size_t k = 0; k < n; ++k) x_m[k] = x_t[k] + e[k];
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(OneFloor(x_m, x_t));
  CHECK(c.J2_pct == doctest::Approx(100.0 * SampleStd(e) / SampleStd(x_t)).epsilon(1e-9));
  CHECK(c.J3_pct == doctest::Approx(100.0 * 0.3 / MaxAbs(x_t)).epsilon(1e-9));
  // An independent figure: the max error is the spike (0.3), its std is that of the square wave + spike.
  CHECK(MaxAbs(e) == 0.3);
  // Here x_r = x_t: J4, J5 equal J2, J3; the one other floor (none here) leaves J6-J9 NaN.
  CHECK(c.J4_pct == doctest::Approx(c.J2_pct).epsilon(1e-12));
  CHECK(c.J5_pct == doctest::Approx(c.J3_pct).epsilon(1e-12));
  CHECK(c.floors.empty());
  CHECK(std::isnan(c.J6_pct));
  CHECK(std::isnan(c.J9_pct));
  // No error at all: exactly zero.
  const BenchmarkCriteria zero = BenchmarkCriteriaFrom(OneFloor(x_t, x_t));
  CHECK(zero.J1_ms == 0.0);
  CHECK(zero.J2_pct == 0.0);
  CHECK(zero.J3_pct == 0.0);
}

TEST_CASE("J2 is the standard deviation, not the RMS: a constant offset does not count, J3 does") {
  const std::vector<double> x_t = Sines(3000);
  std::vector<double> x_m = x_t;
  for (double& v : x_m) v += 0.2;
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(OneFloor(x_m, x_t));
  CHECK(c.J2_pct < 1e-10);
  CHECK(c.J3_pct == doctest::Approx(100.0 * 0.2 / MaxAbs(x_t)).epsilon(1e-9));
}

TEST_CASE("J4-J9 on a constructed 3-story case: each floor's error is its own") {
  const std::size_t n = 4000;
  BenchmarkSignals s;
  s.dt_s = kDt;
  s.actuator_floor = 1;
  const std::vector<double> r1 = Sines(n), r2 = Sines(n, 40.0), r3 = Sines(n, 90.0);
  std::vector<double> r2s = r2, r3s = r3;
  for (double& v : r2s) v *= 1.5;
  for (double& v : r3s) v *= 2.0;
  s.x_r = {r1, r2s, r3s};
  // Numerical floors: floor 1 = the target; floor 2 off by 2 % of itself (std and max both 2 %);
  // floor 3 off by a constant 0.1 (std 0, max 0.1 / max|x_r,3|).
  std::vector<double> n2 = r2s, n3 = r3s;
  for (double& v : n2) v *= 1.02;
  for (double& v : n3) v += 0.1;
  s.x_t = r1;
  s.x_n = {r1, n2, n3};
  // Measured: the reference floor 1 times 0.95 (J4 = J5 = 5 %); target = reference (J2 = J4).
  s.x_m = r1;
  for (double& v : s.x_m) v *= 0.95;
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(s);
  CHECK(c.J4_pct == doctest::Approx(5.0).epsilon(1e-9));
  CHECK(c.J5_pct == doctest::Approx(5.0).epsilon(1e-9));
  CHECK(c.J2_pct == doctest::Approx(5.0).epsilon(1e-9));
  CHECK(c.J6_pct == doctest::Approx(2.0).epsilon(1e-9));
  CHECK(c.J8_pct == doctest::Approx(2.0).epsilon(1e-9));
  CHECK(c.J7_pct < 1e-9);
  CHECK(c.J9_pct == doctest::Approx(100.0 * 0.1 / MaxAbs(r3s)).epsilon(1e-9));
  REQUIRE(c.floors.size() == 2);
  CHECK(c.floors[0].floor == 2);
  CHECK(c.floors[1].floor == 3);
  CHECK(c.floors[1].max_pct == c.J9_pct);
  // The benchmark's floors: Format() names no floors.
  CHECK(c.Format().find("floor") == std::string::npos);

  // The actuator at floor 2: J4/J5 compare x_m with x_r,2; J6/J8 are floor 1, J7/J9 floor 3.
  s.actuator_floor = 2;
  s.x_m = r2s;
  s.x_t = r2s;
  s.x_n = {r1, r2s, n3};
  const BenchmarkCriteria c2 = BenchmarkCriteriaFrom(s);
  CHECK(c2.J4_pct == 0.0);
  REQUIRE(c2.floors.size() == 2);
  CHECK(c2.floors[0].floor == 1);
  CHECK(c2.J6_pct == 0.0);
  CHECK(c2.J9_pct == doctest::Approx(100.0 * 0.1 / MaxAbs(r3s)).epsilon(1e-9));
  CHECK(c2.Format().find("floor 1:") != std::string::npos);  // says which floors J6-J9 are
}

TEST_CASE("more floors: one entry per floor other than the actuator's, J6-J9 the first two") {
  const std::size_t n = 1000;
  BenchmarkSignals s;
  s.dt_s = kDt;
  s.x_m = s.x_t = Sines(n);
  for (int i = 0; i < 5; ++i) {
    std::vector<double> r = Sines(n, 10.0 * i), m = r;
    for (double& v : m) v *= 1.0 + 0.01 * i;  // floor i+1 off by i %
    s.x_r.push_back(r);
    s.x_n.push_back(m);
  }
  s.x_r[0] = s.x_t;
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(s);
  REQUIRE(c.floors.size() == 4);
  for (int i = 0; i < 4; ++i) {
    CAPTURE(i);
    CHECK(c.floors[i].floor == i + 2);
    CHECK(c.floors[i].std_pct == doctest::Approx(i + 1.0).epsilon(1e-9));
  }
  CHECK(c.J6_pct == c.floors[0].std_pct);
  CHECK(c.J7_pct == c.floors[1].std_pct);
  CHECK(c.J8_pct == c.floors[0].max_pct);
  CHECK(c.J9_pct == c.floors[1].max_pct);
}

TEST_CASE("rounding: J1 to 0.1 ms, the others to 0.01 %") {
  BenchmarkCriteria c;
  c.J1_ms = 25.3906;
  c.J2_pct = 12.344999;
  c.J3_pct = 12.345001;
  c.J4_pct = -0.004;
  c.J5_pct = 0.005;
  c.J6_pct = 99.999;
  c.J7_pct = std::nan("");
  c.J8_pct = 1.0;
  c.J9_pct = 0.126;
  c.floors = {{2, 0.1234, 5.6789}};
  const BenchmarkCriteria r = c.Rounded();
  CHECK(r.J1_ms == doctest::Approx(25.4).epsilon(1e-15));
  CHECK(r.J2_pct == doctest::Approx(12.34).epsilon(1e-15));
  CHECK(r.J3_pct == doctest::Approx(12.35).epsilon(1e-15));
  CHECK(r.J4_pct == 0.0);
  CHECK(r.J6_pct == doctest::Approx(100.0).epsilon(1e-15));
  CHECK(std::isnan(r.J7_pct));
  CHECK(r.J9_pct == doctest::Approx(0.13).epsilon(1e-15));
  CHECK(r.floors[0].std_pct == doctest::Approx(0.12).epsilon(1e-15));
  CHECK(r.floors[0].max_pct == doctest::Approx(5.68).epsilon(1e-15));
  const std::string line = c.Format();
  CHECK(line.find("J1 25.4 ms") != std::string::npos);
  CHECK(line.find("J2 12.34 %") != std::string::npos);
  CHECK(line.find("J3 12.35 %") != std::string::npos);
  CHECK(line.find("J7 n/a") != std::string::npos);
  CHECK(line.find("J9 0.13 %") != std::string::npos);
}

TEST_CASE("errors: lengths, too short, zero variance, not finite, floors, dt") {
  const std::vector<double> x = Sines(200);
  BenchmarkSignals ok = OneFloor(x, x);
  CHECK(ErrorOf(ok).empty());

  BenchmarkSignals s = ok;
  s.x_t.pop_back();
  CHECK(ErrorOf(s).find("x_t has 199 samples but x_m has 200") != std::string::npos);
  s = ok;
  s.x_r[0].push_back(0.0);
  CHECK(ErrorOf(s).find("x_r floor 1 has 201 samples") != std::string::npos);

  const std::vector<double> short_x(x.begin(), x.begin() + 50);
  CHECK(ErrorOf(OneFloor(short_x, short_x)).find("50 samples are too few (at least 51") != std::string::npos);
  const std::vector<double> just(x.begin(), x.begin() + 51);
  CHECK(ErrorOf(OneFloor(just, just)).empty());

  s = ok;
  s.x_t.assign(200, 0.0);
  s.x_n = {s.x_t};
  CHECK(ErrorOf(s).find("x_t (the target) does not move") != std::string::npos);
  s = ok;
  s.x_r[0].assign(200, 1.0);  // constant: std 0
  CHECK(ErrorOf(s).find("x_r floor 1 (the reference) does not move") != std::string::npos);

  s = ok;
  s.x_m[17] = std::nan("");
  CHECK(ErrorOf(s).find("x_m is not finite at sample 17") != std::string::npos);

  s = ok;
  s.x_n.clear();
  CHECK(ErrorOf(s).find("x_n has 0 floors and x_r 1") != std::string::npos);
  s = ok;
  s.actuator_floor = 2;
  CHECK(ErrorOf(s).find("actuator_floor = 2 is out of range [1, 1]") != std::string::npos);
  s = ok;
  s.dt_s = 0.0;
  CHECK(ErrorOf(s).find("dt_s = 0 s is out of range") != std::string::npos);

  // A measured signal that never moves: J1 is undefined (NaN, lag -1), the rest are computed.
  s = ok;
  s.x_m.assign(200, 0.0);
  const BenchmarkCriteria c = BenchmarkCriteriaFrom(s);
  CHECK(std::isnan(c.J1_ms));
  CHECK(c.lag_samples == -1);
  CHECK(c.J2_pct == doctest::Approx(100.0));
  CHECK(c.J3_pct == doctest::Approx(100.0));
}

TEST_CASE("PearsonCorrelation: +1, -1, NaN for a constant, length mismatch refused") {
  const std::vector<double> a = {1, 2, 3, 4}, b = {2, 4, 6, 8}, c = {4, 3, 2, 1}, k = {5, 5, 5, 5};
  CHECK(PearsonCorrelation(a, b) == doctest::Approx(1.0));
  CHECK(PearsonCorrelation(a, c) == doctest::Approx(-1.0));
  CHECK(std::isnan(PearsonCorrelation(a, k)));
  CHECK_THROWS_AS(PearsonCorrelation(a, std::vector<double>{1, 2}), rths::Error);
}
