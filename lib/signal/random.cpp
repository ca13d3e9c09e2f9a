#include "signal/random.h"

#include <cmath>
#include <limits>

namespace rths::signal {

GaussianState MakeGaussian(std::uint64_t seed) {
  GaussianState state;
  state.engine.seed(seed);
  return state;
}

double NextUniform(GaussianState* state) {
  return static_cast<double>(state->engine() >> 11) * 0x1.0p-53;
}

double PortableLog(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
  int e = 0;
  double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1): exact
  if (m < 0.70710678118654752440) {
    m *= 2.0;  // exact
    e -= 1;
  }
  // ln m = 2 atanh(s) = 2 (s + s^3/3 + s^5/5 + ...), |s| <= 0.1716, s^2 <= 0.0295:
  // terms up to s^25/25 leave a truncation error below 1e-19 relative.
  const double s = (m - 1.0) / (m + 1.0);
  const double s2 = s * s;
  double series = 1.0 / 25.0;
  for (int k = 11; k >= 0; --k) series = 1.0 / (2.0 * k + 1.0) + s2 * series;
  const double log_m = 2.0 * s * series;
  // ln 2 split (fdlibm): the high part has trailing zero bits, so e * ln2_hi is exact.
  constexpr double kLn2Hi = 6.93147180369123816490e-01;
  constexpr double kLn2Lo = 1.90821492927058770002e-10;
  const double de = static_cast<double>(e);
  return de * kLn2Hi + (de * kLn2Lo + log_m);
}

double NextGaussian(GaussianState* state) {
  if (state->has_spare) {
    state->has_spare = false;
    return state->spare;
  }
  double u = 0.0, v = 0.0, s = 0.0;
  do {
    u = 2.0 * NextUniform(state) - 1.0;
    v = 2.0 * NextUniform(state) - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * PortableLog(s) / s);
  state->spare = v * factor;
  state->has_spare = true;
  return u * factor;
}

}  // namespace rths::signal
