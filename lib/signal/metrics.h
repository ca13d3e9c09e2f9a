#pragma once
/// @file Tracking metrics (docs/experiments.md E3).
#include <cstddef>
#include <span>

namespace rths::signal {

/// Eq. 31, normalised RMS tracking error in percent:
///   e = sqrt( sum_i (r_i - y_i)^2 / sum_i r_i^2 ) x 100 %,
/// r the desired and y the measured displacement (any common unit) at the same steps i.
/// Returns NaN if sum r^2 == 0 (the metric is undefined). Throws rths::Error if the spans
/// differ in length.
double RmsErrorPercent(std::span<const double> r, std::span<const double> y);

/// Root mean square of x, sqrt(sum x_i^2 / n) (0 for no samples).
double Rms(std::span<const double> x);

/// The largest |x_i| over the finite samples (0 if none); `at` (if given) gets its index (0 if
/// none).
double PeakAbs(std::span<const double> x, std::size_t* at = nullptr);

/// Eq. 31 accumulated sample by sample (for a logger). Add() allocates nothing; Percent() is
/// equal to RmsErrorPercent over the samples added so far.
struct RmsErrorAccumulator {
  double sum_error2 = 0.0;      ///< sum (r_i - y_i)^2
  double sum_reference2 = 0.0;  ///< sum r_i^2
  std::size_t count = 0;        ///< samples added

  /// Adds one pair (r_i desired, y_i measured).
  void Add(double r, double y) {
    const double e = r - y;
    sum_error2 += e * e;
    sum_reference2 += r * r;
    ++count;
  }
  /// Eq. 31 so far, in percent; NaN while sum r^2 == 0.
  double Percent() const;
};

}  // namespace rths::signal
