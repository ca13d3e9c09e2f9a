#include "signal/metrics.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::signal {

double RmsErrorAccumulator::Percent() const {
  if (!(sum_reference2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(sum_error2 / sum_reference2) * 100.0;
}

double RmsErrorPercent(std::span<const double> r, std::span<const double> y) {
  if (r.size() != y.size()) {
    throw Error("RmsErrorPercent", fmt::format("r has {} samples and y has {}: they must match",
                                               r.size(), y.size()));
  }
  RmsErrorAccumulator acc;
  for (std::size_t i = 0; i < r.size(); ++i) acc.Add(r[i], y[i]);
  return acc.Percent();
}

double Rms(std::span<const double> x) {
  if (x.empty()) return 0.0;
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

double PeakAbs(std::span<const double> x, std::size_t* at) {
  double peak = 0.0;
  std::size_t where = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isfinite(x[i]) && std::abs(x[i]) > peak) {
      peak = std::abs(x[i]);
      where = i;
    }
  }
  if (at) *at = where;
  return peak;
}

}  // namespace rths::signal
