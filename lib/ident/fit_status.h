#pragma once
/// @file How a damper fit ended, said where a user reads it (`rths identify --damper`,
/// docs/identification.md "When a fit fails"): on the terminal, in the model file (a comment and a
/// `[fit]` table) and in the exit code.
///
/// Every fitted parameter p lies in a box [lo, hi] (the fit searches ln p). At the end each is:
///   - free:      strictly inside the box (|ln p - ln b| > kBoundTolerance for both ends b);
///   - at zero:   on the lower end of a parameter that is physically >= 0 and whose floor stands
///                for 0 (beta, gamma, k0, the laws' ends): the best value is 0, an answer;
///   - at bound:  on any other end (the rates p_c, eta, every upper end): the box, not the data,
///                chose the value;
///   - held:      not fitted, because the records cannot determine it (a filter time constant
///                when no record changes its command; the rates when the records hold two input
///                levels only), held at a stated value;
///   - irrelevant: a rate p_c on a bound whose law has equal ends (p_a = p_b, or both at zero),
///                so that the rate changes nothing.
/// The fit *failed* (Ok() false) if Levenberg-Marquardt did not converge within its iterations or
/// a parameter is `at bound`; `rths identify` then exits with kExitFitFailed unless
/// --accept-unconverged. A fitted value outside the plausible range of an MR damper
/// (plausible_range.h) is *implausible*: a warning, printed and recorded, not a failure.
#include <string>
#include <vector>

#include "core/exit_code.h"

namespace rths::ident {

/// Exit code of `rths identify --damper` for a failed fit (FitStatus::Ok() false).
inline constexpr int kExitFitFailed = rths::kExitFitFailed;  // the one table: core/exit_code.h

/// |ln p - ln b| below which a parameter is on its bound b.
inline constexpr double kBoundTolerance = 1e-6;

/// Where one fitted parameter ended (file comment).
enum class ParameterState { kFree, kAtZero, kAtBound, kHeld, kIrrelevant };

/// One parameter's end state.
struct ParameterStatus {
  std::string name;  ///< as in the model file, e.g. "alpha_c", "k0", "eta_1_s"
  double value = 0.0;
  double lo = 0.0, hi = 0.0;  ///< its box
  ParameterState state = ParameterState::kFree;
  std::string why;            ///< for kHeld and kIrrelevant: the reason
};

/// A fitted value outside its plausible range (plausible_range.h): a warning, not a failure.
struct Implausible {
  std::string name;   ///< as in the model file, e.g. "c0_b"
  double value = 0.0;
  double lo = 0.0, hi = 0.0;  ///< the plausible range at the fit's A (plausible_range.h)
  std::string unit;   ///< e.g. "kN s/mm"
  /// "c0_b = 71.5 kN s/mm is outside the plausible range 0.0001..3.2 kN s/mm (docs/identification.md
  /// \"Plausible ranges\")".
  std::string Warning() const;
};

/// How a fit ended (file comment).
struct FitStatus {
  bool converged = false;
  int iterations = 0;
  int max_iterations = 0;
  std::vector<ParameterStatus> parameters;
  std::vector<Implausible> implausible;  ///< fitted values outside their plausible range (warnings)

  /// Converged, and no parameter at a bound (an implausible value does not make it fail).
  bool Ok() const;
  /// What a figure of the fit says of it, "" for a fit that is ok and plausible: "FIT FAILED:
  /// alpha_c on its bound" (or "not converged", or "alpha_c, beta_c on their bounds"), then
  /// "implausible: c0_b" (at most two names, then "+N": "implausible: c0_b, c0_c +1"), joined by "; ".
  std::string Mark() const;
  /// The names of the parameters in `state`.
  std::vector<std::string> Names(ParameterState state) const;
  /// One line: "ok (converged in 54 iterations)" or "FAILED: not converged (150 iterations, the
  /// limit); alpha_c = 1000 on its upper bound".
  std::string Summary() const;
  /// Lines for the terminal, each starting with `indent`: the summary, then one line per
  /// parameter that is not free (at zero, at bound, held, irrelevant) with its value and why,
  /// then one "warning: ..." line per implausible value.
  std::string Details(const std::string& indent) const;
  /// Model-file comment lines ('#'): the summary and the details; a failed fit's first line
  /// says "FIT FAILED" so that no reader takes the file for a working model.
  std::string Comment() const;
  /// The `[fit]` table: status = "ok" | "failed", converged, iterations, max_iterations and the
  /// lists at_bound, at_zero, held, irrelevant, implausible (parameter names).
  std::string TomlTable() const;
};

/// The state of a fitted parameter from its value and box: kAtZero or kAtBound on the lower end
/// (kAtZero if zero_floor), kAtBound on the upper end, else kFree.
ParameterStatus StatusOf(std::string name, double value, double lo, double hi, bool zero_floor);

}  // namespace rths::ident
