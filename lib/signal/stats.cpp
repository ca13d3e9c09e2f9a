#include "signal/stats.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rths::signal {

Spread SpreadOf(std::span<const double> v) {
  Spread s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) {
    s.mean = s.std = s.min = s.max = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / s.n;
  double ss = 0.0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.std = s.n > 1 ? std::sqrt(ss / (s.n - 1)) : 0.0;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

double StdOfDifference(std::span<const double> a, std::span<const double> b) {
  const std::size_t n = a.size();
  auto at = [&](std::size_t i) { return b.empty() ? a[i] : a[i] - b[i]; };
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += at(i);
  mean /= static_cast<double>(n);
  double ss = 0.0;
  for (std::size_t i = 0; i < n; ++i) ss += (at(i) - mean) * (at(i) - mean);
  return std::sqrt(ss / static_cast<double>(n - 1));
}

double MaxAbsOfDifference(std::span<const double> a, std::span<const double> b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(b.empty() ? a[i] : a[i] - b[i]));
  return m;
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace rths::signal
