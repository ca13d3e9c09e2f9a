#pragma once
/// @file The derivative of a sampled record by finite differences (offline: allocates).
#include <span>
#include <vector>

namespace rths::signal {

/// dx/dt of samples x at step dt_s [unit/s]: the second-order central difference
/// (x_{k+1} - x_{k-1}) / (2 dt) inside, the one-sided (x_1 - x_0) / dt and
/// (x_{n-1} - x_{n-2}) / dt at the ends; all zeros for fewer than 2 samples.
std::vector<double> Derivative(std::span<const double> x, double dt_s);

}  // namespace rths::signal
