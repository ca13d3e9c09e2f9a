#pragma once
/// @file The plausible range of each fitted parameter of the Spencer MR damper model (Eqs. 32-39)
/// for an MR damper of 1-1000 kN (docs/identification.md "Plausible ranges", where the sources are).
/// Indicative, not a law: a decade either side of the published values of three dampers (Table 3's
/// 200 kN damper, Spencer et al. 1997's prototype, our fits of the UTFSM 1.5 kN damper). A fitted
/// value outside its range is flagged (FitStatus::implausible, a warning), not refused. Units: mm,
/// kN, s, A.
///
/// alpha, beta and gamma scale with A (for n = 2, z -> z / s, A -> A / s, alpha, beta, gamma -> s x
/// the same: damper_fit.h), so their ranges are stated at A = 300 (Table 3's and the fits' default)
/// and scale by 300 / A at another A.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ident/fit_status.h"

namespace rths::ident {

/// The A the ranges of alpha, beta and gamma are stated at.
inline constexpr double kPlausibleRangeA = 300.0;

/// One parameter's plausible range, at the fit's A.
struct PlausibleRange {
  double lo = 0.0, hi = 0.0;  ///< lo 0: the parameter may vanish
  std::string unit;           ///< "kN/mm", "kN s/mm", "1/mm^2", "1/A", "1/s"
};

/// The range of a parameter by its model-file name: "alpha", "c0", "c1", "k0", "k1", "beta",
/// "gamma" (the fit at one current), their law ends "alpha_a", "c0_b", ... (the value at the lowest
/// and highest input), the rates "alpha_c", ... (per A: a current input only) and "eta_1_s".
/// Unset for a name it does not know, for x0 and for a rate of a voltage input (no published
/// exponential law in volts). A > 0 is the fit's Bouc-Wen A.
std::optional<PlausibleRange> PlausibleRangeOf(std::string_view name, double A, bool voltage);

/// The values among `values` (name, value) outside their plausible range, in the given order.
std::vector<Implausible> CheckPlausible(const std::vector<std::pair<std::string, double>>& values, double A,
                                        bool voltage);

/// The (name, value) of the parameters of `status` that the data chose (free), plus the extra
/// ones given (k1, which the fits solve apart): what CheckPlausible judges. A parameter at zero,
/// at a bound (already a failure), held or irrelevant is not judged, nor a rate p_c whose law is
/// flat (p_a and p_b both at zero, or equal within 0.1 %: the rate changes nothing).
std::vector<std::pair<std::string, double>> FittedValues(const FitStatus& status,
                                                         std::vector<std::pair<std::string, double>> extra = {});

}  // namespace rths::ident
