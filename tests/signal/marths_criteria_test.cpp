// The maRTHS criteria (lib/signal/marths_criteria.h): finddelay's lag and tie rules, J1-J10 on
// records whose answers are known.
#include <cmath>
#include <vector>

#include <doctest/doctest.h>

#include "signal/marths_criteria.h"

using rths::signal::FindDelay;

namespace {

std::vector<double> Wave(int n, int shift) {
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) {
    const double t = (i - shift) / 1024.0;
    x[i] = std::sin(2 * 3.14159265358979 * 1.7 * t) * std::exp(-0.2 * t) + 0.3 * std::sin(23.0 * t);
  }
  return x;
}

}  // namespace

TEST_CASE("finddelay: a delayed copy gives its delay, an advanced one a negative delay, beyond the first window too") {
  const auto x = Wave(4000, 0);
  CHECK(FindDelay(x, Wave(4000, 5), 1024) == 5);
  CHECK(FindDelay(x, Wave(4000, -3), 1024) == -3);
  CHECK(FindDelay(x, x, 1024) == 0);
  // With a window of 10 lags the best (40) lies beyond it: the search widens to every lag.
  CHECK(FindDelay(x, Wave(4000, 40), 10) == 40);
  // An inverted copy counts (|correlation|), as MATLAB's finddelay does.
  auto neg = Wave(4000, 7);
  for (double& v : neg) v = -v;
  CHECK(FindDelay(x, neg, 1024) == 7);
  // Ties: a symmetric pulse between two equal copies goes to the smaller |lag|, then the positive.
  std::vector<double> a(21, 0.0), b(21, 0.0);
  a[10] = 1.0;
  b[8] = 1.0;
  b[12] = 1.0;
  CHECK(FindDelay(a, b, 5) == 2);
  CHECK_THROWS(FindDelay(a, std::vector<double>(20, 0.0), 5));
}

TEST_CASE("J1-J10 of records with known errors") {
  const int n = 3000;
  rths::signal::MarthsSignals s;
  s.dt_s = 1.0 / 1024;
  const auto w = Wave(n, 0), w3 = Wave(n, 3);
  s.xa1_t = w;
  s.xa1_m = w3;                       // 3 samples late
  s.xa2_t = w;
  s.xa2_m = w;
  for (double& v : s.xa2_m) v *= 1.1;  // 10 % too large: J2 = J3 = 10 %
  s.x_num = w;
  s.x_hat = w;
  s.x_ref = w;
  for (double& v : s.x_hat) v *= 0.95;  // J5 = J6 = J7 = J9 = 5 %
  s.r_num = s.r_ref = s.r_hat = w;
  s.x2_num = s.x2_ref = s.r2_num = s.r2_ref = s.x3_num = s.x3_ref = s.r3_num = s.r3_ref = w;
  for (double& v : s.x3_num) v *= 1.02;  // J8,X3 = J10,X3 = 2 %
  const auto j = rths::signal::MarthsCriteriaFrom(s);
  CHECK(j.J1_1_ms == doctest::Approx(3000.0 / 1024));
  CHECK(j.J1_2_ms == 0.0);
  CHECK(j.J2_2_pct == doctest::Approx(10.0));
  CHECK(j.J3_2_pct == doctest::Approx(10.0));
  CHECK(j.J5_X_pct == doctest::Approx(5.0));
  CHECK(j.J6_X_pct == doctest::Approx(5.0));
  CHECK(j.J7_X_pct == doctest::Approx(5.0));
  CHECK(j.J9_X_pct == doctest::Approx(5.0));
  CHECK(j.J5_TH_pct == 0.0);
  CHECK(j.J8_X3_pct == doctest::Approx(2.0));
  CHECK(j.J10_X3_pct == doctest::Approx(2.0));
  CHECK(j.J8_X2_pct == 0.0);
  CHECK(j.Items().size() == 22);
  CHECK(j.Items()[0].first == "J1_1_ms");
  s.x_ref.assign(n, 0.0);
  CHECK_THROWS_WITH(rths::signal::MarthsCriteriaFrom(s), doctest::Contains("J7,X"));
}
