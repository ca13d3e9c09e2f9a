#pragma once
/// @file The supply ripple's closed-form fit (docs/diagnosis.md "Supply ripple"): a periodic motion
/// at a pump's frequency f and its harmonics (models::SupplyRipple), whose amplitude and phase per
/// harmonic are fitted per record by linear least squares (a pump is not synchronised with the
/// test), and whose frequency comes from the residual's harmonic spectrum. Offline analysis: these
/// functions allocate.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "models/rig_effects.h"

namespace rths::diagnosis {

/// A record's ripple: r_k = sum_h s_h sin(2 pi h f t_k) + c_h cos(2 pi h f t_k), h = 1 ..
/// models::kRippleHarmonics, t_k = k dt (k from the record's first sample).
struct RippleFit {
  double f_hz = 0.0;
  std::array<double, 2 * models::kRippleHarmonics> coef{};  ///< s_1, c_1, s_2, c_2, ... [mm]
  /// The fundamental's amplitude sqrt(s_1^2 + c_1^2) [mm].
  double FundamentalAmplitude() const;
  /// r_k [mm], its first and second time derivatives [mm/s], [mm/s^2] at sample k (dt [s]).
  double Value(std::size_t k, double dt_s) const;
  double Rate(std::size_t k, double dt_s) const;
  double Acceleration(std::size_t k, double dt_s) const;
  /// Adds r_k to y_k for k = 0 .. y.size() - 1, and its rate to v_k and acceleration to a_k where
  /// v, a are not empty (the same length as y).
  void AddTo(double dt_s, std::span<double> y, std::span<double> v = {}, std::span<double> a = {}) const;
};

/// The least-squares ripple at f_hz in the residual e over k >= first (the normal equations of the
/// 2 H sines and cosines, with a ridge of 1e-9 of their mean diagonal). A harmonic at or above the
/// Nyquist frequency is not fitted (its coefficients 0: models::RippleHarmonicSampled).
RippleFit FitRipple(std::span<const double> e, double dt_s, double f_hz, std::size_t first);

/// Sum over k >= first of (e_k - r_k)^2 for the least-squares ripple r at f_hz.
double RippleSse(std::span<const double> e, double dt_s, double f_hz, std::size_t first);

/// The frequency in [lo_hz, hi_hz] that maximises the harmonic sum of the residuals' spectra,
/// sum_records sum_h |E(h f)|^2 over the harmonics below the Nyquist frequency, with E the DFT of the Hann-windowed residual over k >= first,
/// zero-padded to at least twice the longest record (so that h f falls on a bin when f does);
/// lo_hz if no bin lies in the range. All residuals share dt_s.
double RipplePeakHz(const std::vector<std::vector<double>>& e, const std::vector<std::size_t>& first, double dt_s,
                    double lo_hz, double hi_hz);

}  // namespace rths::diagnosis
