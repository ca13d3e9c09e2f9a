#pragma once
/// @file Summary statistics of a set of values (a criterion over a study's runs, timings of a
/// bench): mean, sample standard deviation, extremes, median.
#include <span>
#include <vector>

namespace rths::signal {

/// Mean, sample standard deviation (n - 1), min and max of n values, in the values' unit.
struct Spread {
  double mean = 0.0, std = 0.0, min = 0.0, max = 0.0;
  int n = 0;
};

/// The spread of v: mean = sum / n, std = sqrt(sum (v - mean)^2 / (n - 1)) (0 for one value),
/// min and max; every field NaN (n = 0) for no values.
Spread SpreadOf(std::span<const double> v);

/// Sample standard deviation (n - 1, two passes) of a - b, or of a when b is empty; a and b of
/// equal length >= 2 (not checked).
double StdOfDifference(std::span<const double> a, std::span<const double> b);

/// max |a - b|, or max |a| when b is empty (0 for no values).
double MaxAbsOfDifference(std::span<const double> a, std::span<const double> b);

/// The median of v: its middle value after sorting, the mean of the two middle ones for an even
/// count; NaN for no values.
double Median(std::vector<double> v);

}  // namespace rths::signal
