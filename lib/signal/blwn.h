#pragma once
/// @file Band-limited white noise, the convention for every test record (docs/models.md section 9).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rths::signal {

/// Band-limited white noise of n samples at step dt_s [s]:
///   1. w_j ~ N(0, 1), j = 0 .. m + n - 1, from MakeGaussian(seed) (signal/random.h), with
///      m = round(discard_s / dt_s) start-up samples;
///   2. v = causal 8th-order Butterworth low-pass at band_hz, fs = 1/dt_s, as four biquads
///      (signal/butterworth.h), starting at rest;
///   3. keep v_m .. v_{m+n-1} (the filter's start-up transient is thrown away);
///   4. scale so that sqrt(mean(x^2)) over the kept n samples equals `rms` (to rounding).
/// The unit of `rms` is the signal's (mm for a desired displacement, mm/s^2 for a ground
/// acceleration). Same seed, same arguments: the same record on any compiler.
/// Throws rths::Error if dt_s is not > 0, band_hz not in (0, 0.5/dt_s), rms not > 0,
/// n == 0, or discard_s not in [0, 1e6].
std::vector<double> Blwn(double band_hz, double rms, double dt_s, std::size_t n, std::uint64_t seed,
                         double discard_s);

}  // namespace rths::signal
