#include "signal/bode.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::signal {

BodeCurve BodeFromResponse(const std::string& name, std::span<const double> f_hz,
                           std::span<const std::complex<double>> h, std::span<const double> coherence) {
  if (f_hz.size() != h.size() || (!coherence.empty() && coherence.size() != h.size()))
    throw Error("BodeFromResponse", fmt::format("{} frequencies, {} responses, {} coherences: lengths differ",
                                                f_hz.size(), h.size(), coherence.size()));
  BodeCurve c;
  c.name = name;
  c.f_hz.assign(f_hz.begin(), f_hz.end());
  const std::vector<double> phase = UnwrapPhase(h);
  for (std::size_t i = 0; i < h.size(); ++i) {
    c.magnitude.push_back(std::abs(h[i]));
    c.phase_deg.push_back(phase[i] * 180.0 / std::numbers::pi);
    c.lag_ms.push_back(-phase[i] / (2.0 * std::numbers::pi * f_hz[i]) * 1e3);
    c.coherence.push_back(coherence.empty() ? 1.0 : coherence[i]);
  }
  return c;
}

BodeCurve BodeBand(const BodeCurve& c, double lo_hz, double hi_hz) {
  BodeCurve b;
  b.name = c.name;
  for (std::size_t i = 0; i < c.f_hz.size(); ++i) {
    if (!(c.f_hz[i] > 0.0 && c.f_hz[i] >= lo_hz && c.f_hz[i] <= hi_hz)) continue;
    b.f_hz.push_back(c.f_hz[i]);
    b.magnitude.push_back(c.magnitude[i]);
    b.phase_deg.push_back(c.phase_deg[i]);
    b.lag_ms.push_back(c.lag_ms[i]);
    b.coherence.push_back(c.coherence[i]);
  }
  return b;
}

BodeCurve BodeFromEstimate(const std::string& name, const FrequencyResponseEstimate& est, double f_max_hz) {
  std::vector<double> f, coherence;
  std::vector<std::complex<double>> h;
  for (std::size_t i = 1; i < est.f_hz.size() && est.f_hz[i] <= f_max_hz + 1e-9; ++i) {
    f.push_back(est.f_hz[i]);
    h.push_back(est.h[i]);
    coherence.push_back(est.coherence[i]);
  }
  return BodeFromResponse(name, f, h, coherence);
}

}  // namespace rths::signal
