#include "signal/butterworth.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::signal {

Sos ButterworthLowpass(int order, double fc_hz, double fs_hz) {
  if (order < 1 || order > 32) {
    throw Error("ButterworthLowpass", fmt::format("order = {}: allowed [1, 32]", order));
  }
  if (!(fs_hz > 0.0) || !std::isfinite(fs_hz)) {
    throw Error("ButterworthLowpass", fmt::format("fs_hz = {}: allowed > 0", fs_hz));
  }
  if (!(fc_hz > 0.0) || !(fc_hz < 0.5 * fs_hz)) {
    throw Error("ButterworthLowpass",
                fmt::format("fc_hz = {}: allowed (0, {}) (below fs/2)", fc_hz, 0.5 * fs_hz));
  }
  const double pi = std::numbers::pi;
  const double k = std::tan(pi * fc_hz / fs_hz);  // prewarped W_c / (2 fs)
  const double k2 = k * k;
  Sos sos;
  sos.sections.reserve(static_cast<std::size_t>((order + 1) / 2));
  if (order % 2 == 1) {
    // W_c / (s + W_c)  ->  K (1 + z^-1) / ((1 + K) + (K - 1) z^-1)
    const double norm = 1.0 / (1.0 + k);
    Biquad bq;
    bq.b0 = k * norm;
    bq.b1 = k * norm;
    bq.b2 = 0.0;
    bq.a1 = (k - 1.0) * norm;
    bq.a2 = 0.0;
    sos.sections.push_back(bq);
  }
  // W_c^2 / (s^2 + q W_c s + W_c^2), q = 2 sin(theta_k):
  //   K^2 (1 + z^-1)^2 / ((1 + q K + K^2) + 2 (K^2 - 1) z^-1 + (1 - q K + K^2) z^-2)
  // Largest theta (most damped, lowest Q) first.
  for (int pair = order / 2 - 1; pair >= 0; --pair) {
    const double theta = (2.0 * pair + 1.0) * pi / (2.0 * order);
    const double q = 2.0 * std::sin(theta);
    const double norm = 1.0 / (1.0 + q * k + k2);
    Biquad bq;
    bq.b0 = k2 * norm;
    bq.b1 = 2.0 * k2 * norm;
    bq.b2 = k2 * norm;
    bq.a1 = 2.0 * (k2 - 1.0) * norm;
    bq.a2 = (1.0 - q * k + k2) * norm;
    sos.sections.push_back(bq);
  }
  return sos;
}

std::complex<double> SosResponse(const Sos& sos, double f_hz, double fs_hz) {
  const double w = 2.0 * std::numbers::pi * f_hz / fs_hz;
  const std::complex<double> z1 = std::polar(1.0, -w);
  const std::complex<double> z2 = z1 * z1;
  std::complex<double> h = 1.0;
  for (const Biquad& s : sos.sections) {
    h *= (s.b0 + s.b1 * z1 + s.b2 * z2) / (1.0 + s.a1 * z1 + s.a2 * z2);
  }
  return h;
}

SosFilter SosAtRest(const Sos& sos) {
  SosFilter state;
  state.z.assign(sos.sections.size(), {0.0, 0.0});
  return state;
}

double SosStep(const Sos& sos, SosFilter* state, double x) {
  const std::size_t n = sos.sections.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Biquad& s = sos.sections[i];
    std::array<double, 2>& z = state->z[i];
    const double y = s.b0 * x + z[0];
    z[0] = s.b1 * x - s.a1 * y + z[1];
    z[1] = s.b2 * x - s.a2 * y;
    x = y;
  }
  return x;
}

}  // namespace rths::signal
