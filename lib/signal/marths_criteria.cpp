#include "signal/marths_criteria.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/stats.h"

namespace rths::signal {

namespace {

/// |sum_n x(n) y(n + d)| over the overlap.
double LagProduct(std::span<const double> x, std::span<const double> y, long d) {
  const long n = static_cast<long>(x.size());
  const long lo = std::max(0L, -d), hi = std::min(n, n - d);
  double sum = 0.0;
  for (long i = lo; i < hi; ++i) sum += x[i] * y[i + d];
  return std::abs(sum);
}

/// The best lag in [-w, w] by the file comment's rule.
long BestLag(std::span<const double> x, std::span<const double> y, long w) {
  long best = 0;
  double best_c = LagProduct(x, y, 0);
  for (long a = 1; a <= w; ++a) {
    for (long d : {a, -a}) {  // smaller |d| first, the positive one first: a tie keeps the earlier
      const double c = LagProduct(x, y, d);
      if (c > best_c) best_c = c, best = d;
    }
  }
  return best;
}

double Ratio(double num, double den, const char* what) {
  if (!(den > 0.0)) throw Error("maRTHS criteria", fmt::format("{}: the denominator is zero", what));
  return 100.0 * num / den;
}

/// 100 std(a - b) / std(b).
double StdPct(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  return Ratio(StdOfDifference(a, b), StdOfDifference(b, {}), what);
}

/// 100 max|a - b| / max|b|.
double MaxPct(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  return Ratio(MaxAbsOfDifference(a, b), MaxAbsOfDifference(b, {}), what);
}

}  // namespace

int FindDelay(std::span<const double> x, std::span<const double> y, int first_window) {
  if (x.size() != y.size() || x.size() < 2) throw Error("finddelay", "needs two records of equal length >= 2");
  const long n = static_cast<long>(x.size());
  const long w = std::clamp<long>(first_window, 1, n - 1);
  long d = BestLag(x, y, w);
  if ((d == w || d == -w) && w < n - 1) d = BestLag(x, y, n - 1);
  return static_cast<int>(d);
}

std::vector<std::pair<std::string, double>> MarthsCriteria::Items() const {
  return {{"J1_1_ms", J1_1_ms},       {"J1_2_ms", J1_2_ms},       {"J2_1_pct", J2_1_pct},
          {"J2_2_pct", J2_2_pct},     {"J3_1_pct", J3_1_pct},     {"J3_2_pct", J3_2_pct},
          {"J5_X_pct", J5_X_pct},     {"J5_TH_pct", J5_TH_pct},   {"J6_X_pct", J6_X_pct},
          {"J6_TH_pct", J6_TH_pct},   {"J7_X_pct", J7_X_pct},     {"J7_TH_pct", J7_TH_pct},
          {"J8_X2_pct", J8_X2_pct},   {"J8_TH2_pct", J8_TH2_pct}, {"J8_X3_pct", J8_X3_pct},
          {"J8_TH3_pct", J8_TH3_pct}, {"J9_X_pct", J9_X_pct},     {"J9_TH_pct", J9_TH_pct},
          {"J10_X2_pct", J10_X2_pct}, {"J10_TH2_pct", J10_TH2_pct}, {"J10_X3_pct", J10_X3_pct},
          {"J10_TH3_pct", J10_TH3_pct}};
}

MarthsCriteria MarthsCriteriaFrom(const MarthsSignals& s) {
  const std::size_t n = s.xa1_t.size();
  for (const auto* v : {&s.xa2_t, &s.xa1_m, &s.xa2_m, &s.x_hat, &s.r_hat, &s.x_num, &s.r_num, &s.x_ref,
                        &s.r_ref, &s.x2_num, &s.r2_num, &s.x3_num, &s.r3_num, &s.x2_ref, &s.r2_ref,
                        &s.x3_ref, &s.r3_ref}) {
    if (v->size() != n) throw Error("maRTHS criteria", "records of different lengths");
  }
  if (n < 2) throw Error("maRTHS criteria", "fewer than 2 samples");
  if (!(s.dt_s > 0.0)) throw Error("maRTHS criteria", "dt_s must be > 0");
  const int window = static_cast<int>(std::lround(1.0 / s.dt_s));
  MarthsCriteria j;
  j.J1_1_ms = FindDelay(s.xa1_t, s.xa1_m, window) * s.dt_s * 1000.0;
  j.J1_2_ms = FindDelay(s.xa2_t, s.xa2_m, window) * s.dt_s * 1000.0;
  j.J2_1_pct = StdPct(s.xa1_m, s.xa1_t, "J2,1");
  j.J2_2_pct = StdPct(s.xa2_m, s.xa2_t, "J2,2");
  j.J3_1_pct = MaxPct(s.xa1_m, s.xa1_t, "J3,1");
  j.J3_2_pct = MaxPct(s.xa2_m, s.xa2_t, "J3,2");
  j.J5_X_pct = StdPct(s.x_hat, s.x_num, "J5,X");
  j.J5_TH_pct = StdPct(s.r_hat, s.r_num, "J5,THETA");
  j.J6_X_pct = MaxPct(s.x_hat, s.x_num, "J6,X");
  j.J6_TH_pct = MaxPct(s.r_hat, s.r_num, "J6,THETA");
  j.J7_X_pct = StdPct(s.x_hat, s.x_ref, "J7,X");
  j.J7_TH_pct = StdPct(s.r_hat, s.r_ref, "J7,THETA");
  j.J8_X2_pct = StdPct(s.x2_num, s.x2_ref, "J8,X2");
  j.J8_TH2_pct = StdPct(s.r2_num, s.r2_ref, "J8,THETA2");
  j.J8_X3_pct = StdPct(s.x3_num, s.x3_ref, "J8,X3");
  j.J8_TH3_pct = StdPct(s.r3_num, s.r3_ref, "J8,THETA3");
  j.J9_X_pct = MaxPct(s.x_hat, s.x_ref, "J9,X");
  j.J9_TH_pct = MaxPct(s.r_hat, s.r_ref, "J9,THETA");
  j.J10_X2_pct = MaxPct(s.x2_num, s.x2_ref, "J10,X2");
  j.J10_TH2_pct = MaxPct(s.r2_num, s.r2_ref, "J10,THETA2");
  j.J10_X3_pct = MaxPct(s.x3_num, s.x3_ref, "J10,X3");
  j.J10_TH3_pct = MaxPct(s.r3_num, s.r3_ref, "J10,THETA3");
  return j;
}

}  // namespace rths::signal
