#pragma once
/// @file Digital Butterworth low-pass as cascaded second-order sections (docs/models.md section 9).
///
/// Design: the analog Butterworth prototype of order N,
///   |H_a(j W)|^2 = 1 / (1 + (W / W_c)^(2N)),
/// whose poles come in conjugate pairs s^2 + 2 sin(theta_k) W_c s + W_c^2, theta_k = (2k + 1) pi / (2N),
/// k = 0 .. floor(N/2) - 1, plus one real pole s + W_c when N is odd; mapped to z by the bilinear
/// transform s = 2 fs (1 - z^-1)/(1 + z^-1) with the cutoff prewarped, W_c = 2 fs tan(pi fc / fs),
/// so the digital filter is exactly -3 dB at fc and
///   |H(e^{j 2 pi f / fs})|^2 = 1 / (1 + (tan(pi f / fs) / tan(pi fc / fs))^(2N)).
/// Each section is run in direct form II transposed. A cascade of sections stays accurate at
/// low fc / fs where the expanded transfer function does not (docs/models.md section 9).
#include <array>
#include <complex>
#include <vector>

namespace rths::signal {

/// One second-order section H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2).
/// A first-order section has b2 = a2 = 0.
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0;
  double a1 = 0.0, a2 = 0.0;
};

/// Immutable cascade description: H(z) = product of the sections, applied in order.
struct Sos {
  std::vector<Biquad> sections;
};

/// Butterworth low-pass of order N at cutoff fc [Hz] for sample rate fs [Hz], bilinear with
/// prewarping at fc. Sections: the real pole first (odd N), then the pairs by increasing Q.
/// DC gain is exactly 1 per section (up to rounding).
/// Throws rths::Error if order is not in [1, 32], fs_hz is not > 0, or fc_hz not in (0, fs/2).
Sos ButterworthLowpass(int order, double fc_hz, double fs_hz);

/// Frequency response of the cascade at f [Hz] (z = exp(j 2 pi f / fs)); for design checks.
std::complex<double> SosResponse(const Sos& sos, double f_hz, double fs_hz);

/// Per-step filter state: the two DF-II-T delay registers of each section.
struct SosFilter {
  std::vector<std::array<double, 2>> z;  ///< dim sos.sections.size()
};

/// State at rest (all registers zero), sized for `sos`. Allocates once.
SosFilter SosAtRest(const Sos& sos);

/// One sample through the cascade (direct form II transposed, per section:
/// y = b0 x + z1; z1 = b1 x - a1 y + z2; z2 = b2 x - a2 y). `state` must come from
/// SosAtRest(sos). Allocates nothing.
double SosStep(const Sos& sos, SosFilter* state, double x);

}  // namespace rths::signal
