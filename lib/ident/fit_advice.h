#pragma once
/// @file What to try when a damper fit fails or gives an implausible value (`rths identify
/// --damper`, docs/identification.md "When a fit fails"): for each parameter on a bound of its
/// range, or outside its plausible range (plausible_range.h), which records would determine it
/// (from the part it plays in Eqs. 32-39, after Spencer et al. 1997) and how to hold it (`--hold
/// name=value`, with a value where the records' design gives one); for a fit that did not converge,
/// what that means; and `--accept-unconverged`. Units: mm, kN, s, A (V for a voltage input).
#include <string>
#include <string_view>
#include <vector>

#include "ident/fit_status.h"

namespace rths::ident {

/// What the advice needs to know of a fit beyond its status.
struct AdviceContext {
  bool any_input = false;  ///< the fit with any input history (else at one current)
  bool voltage = false;    ///< its input is a voltage [V] (else a current [A])
  double input_min = 0.0, input_max = 0.0;  ///< the range of the commands fitted [A or V] (any input)
  std::vector<double> levels;  ///< the records' constant input levels, ascending; empty if a command varies
  double current_A = 0.0;      ///< the fit at one current: its current [A]
  double A = 300.0;            ///< the fit's Bouc-Wen A (the plausible ranges of alpha, beta, gamma scale with it)
};

/// Which records determine a parameter (its model-file name: "c0", "c0_b", "alpha_c", "eta_1_s",
/// ...), as one clause: the part it plays in the model and where (which input) to measure it.
std::string WhatDetermines(std::string_view name, const AdviceContext& c);

/// Advice for a parameter on a bound of its range (ParameterState::kAtBound): what the bound
/// means, which records would determine it, and `--hold name=value` (with a value for a rate,
/// from the records' input levels). One line, no newline.
std::string BoundAdvice(const ParameterStatus& p, const AdviceContext& c);

/// Advice for an implausible value of `status`: which records would determine it, and `--hold`;
/// for a law's saturated end p_b whose rate puts it beyond the inputs fitted, says so. One line.
std::string ImplausibleAdvice(const Implausible& p, const FitStatus& status, const AdviceContext& c);

/// Every line of advice for a fit, in order: one per parameter on a bound, one if it did not
/// converge, one per implausible value, and `--accept-unconverged` if it failed. Empty for a fit
/// that is ok and plausible.
std::vector<std::string> FitAdvice(const FitStatus& status, const AdviceContext& c);

}  // namespace rths::ident
