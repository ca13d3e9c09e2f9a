#include "signal/derivative.h"

namespace rths::signal {

std::vector<double> Derivative(std::span<const double> x, double dt_s) {
  const std::size_t n = x.size();
  std::vector<double> v(n, 0.0);
  if (n < 2) return v;
  v[0] = (x[1] - x[0]) / dt_s;
  v[n - 1] = (x[n - 1] - x[n - 2]) / dt_s;
  for (std::size_t k = 1; k + 1 < n; ++k) v[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt_s);
  return v;
}

}  // namespace rths::signal
