#include "signal/blwn.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/butterworth.h"
#include "signal/random.h"

namespace rths::signal {

std::vector<double> Blwn(double band_hz, double rms, double dt_s, std::size_t n, std::uint64_t seed,
                         double discard_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw Error("Blwn", fmt::format("dt_s = {}: allowed > 0", dt_s));
  }
  if (!(band_hz > 0.0) || !(band_hz < 0.5 / dt_s)) {
    throw Error("Blwn", fmt::format("band_hz = {}: allowed (0, {}) (below the Nyquist frequency)",
                                    band_hz, 0.5 / dt_s));
  }
  if (!(rms > 0.0) || !std::isfinite(rms)) {
    throw Error("Blwn", fmt::format("rms = {}: allowed > 0", rms));
  }
  if (n == 0) throw Error("Blwn", "n = 0: allowed >= 1");
  if (!(discard_s >= 0.0) || !(discard_s <= 1e6)) {
    throw Error("Blwn", fmt::format("discard_s = {}: allowed [0, 1e6]", discard_s));
  }
  constexpr int kOrder = 8;
  const Sos sos = ButterworthLowpass(kOrder, band_hz, 1.0 / dt_s);
  SosFilter filter = SosAtRest(sos);
  GaussianState noise = MakeGaussian(seed);
  const auto m = static_cast<std::size_t>(std::llround(discard_s / dt_s));
  for (std::size_t j = 0; j < m; ++j) SosStep(sos, &filter, NextGaussian(&noise));
  std::vector<double> x(n);
  double sum2 = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    x[j] = SosStep(sos, &filter, NextGaussian(&noise));
    sum2 += x[j] * x[j];
  }
  if (!(sum2 > 0.0) || !std::isfinite(sum2)) {
    throw Error("Blwn", fmt::format("the filtered noise has mean square {}; cannot scale it", sum2));
  }
  const double gain = rms / std::sqrt(sum2 / static_cast<double>(n));
  for (double& v : x) v *= gain;
  return x;
}

}  // namespace rths::signal
