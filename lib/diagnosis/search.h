#pragma once
/// @file The minimisers of the effect fits (internal to lib/diagnosis): a grid then golden section
/// for one parameter, Nelder-Mead for two.
#include <functional>
#include <vector>

#include "diagnosis/stages.h"

namespace rths::diagnosis::stages {

/// Minimises f over [s.lo, s.hi] (log axis if s.log): a grid of s.grid points, then golden-section
/// (golden_iters iterations) between the neighbours of the best grid point. Returns the argmin;
/// *fbest its value. `extra` points (e.g. the current value) are added to the grid.
double Minimise1D(const std::function<double(double)>& f, const ParamSpec& s, int golden_iters, double* fbest,
                  std::vector<double> extra = {});

/// The search range `range` narrowed to a bracket around v: [v / factor, v x factor] on a log axis,
/// v +- fraction x (hi - lo) on a linear one, within the range, with `grid` points.
ParamSpec BracketAround(const ParamSpec& range, double v, double factor, double fraction, int grid);

/// Nelder-Mead on two variables (the simplex from x0 with steps dx), `evals` function evaluations
/// at most. Returns the best point; *fbest its value.
std::vector<double> NelderMead2(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                                const std::vector<double>& dx, int evals, double* fbest);

}  // namespace rths::diagnosis::stages
