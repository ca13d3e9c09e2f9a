#pragma once
/// @file The time lag of a frequency response, -phase(f) / (2 pi f), with the phase unwrapped
/// from DC: shared by the linear servo (servo_linear.h) and the benchmark plant (benchmark_plant.h).
#include <cmath>
#include <complex>
#include <numbers>

namespace rths::models {

/// -phase(f_hz) / (2 pi f_hz) [s] of a response `h(f)` that is real and positive at DC, where it
/// equals `dc`. The phase is unwrapped by summing arg(h_i / h_{i-1}) along the grid
/// f_i = f_hz i / n, n = 16 + ceil(8 f_hz): each increment stays far below pi for the smooth,
/// low-order responses this is used on. f_hz > 0 (the callers check it).
template <class Response>
double UnwrappedLagS(double f_hz, std::complex<double> dc, Response h) {
  const int n = 16 + static_cast<int>(std::ceil(8.0 * f_hz));
  std::complex<double> prev = dc;
  double phase = 0.0;
  for (int i = 1; i <= n; ++i) {
    const std::complex<double> hi = h(f_hz * i / n);
    phase += std::arg(hi / prev);
    prev = hi;
  }
  return -phase / (2.0 * std::numbers::pi * f_hz);
}

}  // namespace rths::models
