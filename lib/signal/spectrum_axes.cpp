#include "signal/spectrum_axes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rths::signal {

SpectrumAxes SpectrumAxesOf(const std::vector<double>& f, const std::vector<double>& reference,
                            const std::vector<const std::vector<double>*>& curves, double band_db, double widen,
                            double decades) {
  SpectrumAxes a;
  const std::size_t n = f.size();
  if (n < 3) return a;
  a.f_lo_hz = f[1];
  a.f_hi_hz = f[n - 1];
  if (reference.size() == n) {
    double peak = 0;
    for (std::size_t i = 1; i < n; ++i) peak = std::max(peak, reference[i]);
    const double floor = peak * std::pow(10.0, -band_db / 10.0);
    std::size_t last = 1;
    for (std::size_t i = 1; i < n; ++i) {
      if (reference[i] >= floor && peak > 0) last = i;
    }
    a.f_hi_hz = std::min(f[n - 1], std::max(f[std::min(n - 1, last + 1)], widen * f[last]));
  }
  double hi = 0, lo = std::numeric_limits<double>::infinity();
  for (const auto* c : curves) {
    if (c == nullptr || c->size() != n) continue;
    for (std::size_t i = 1; i < n && f[i] <= a.f_hi_hz; ++i) {
      const double v = (*c)[i];
      if (!std::isfinite(v) || v <= 0) continue;
      hi = std::max(hi, v);
      lo = std::min(lo, v);
    }
  }
  if (hi <= 0) return a;
  a.psd_hi = 2 * hi;
  a.psd_lo = std::max(lo, hi * std::pow(10.0, -decades)) / 2;
  return a;
}

}  // namespace rths::signal
