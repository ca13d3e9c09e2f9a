#pragma once
/// @file The options of the MR damper fits (`rths identify --damper`, docs/identification.md "The
/// MR damper"): one struct and one check for both fits, at one current (FitDamper, damper_fit.h)
/// and with any input history (FitSpencer, spencer_fit.h); FitDamperModel (damper_model.h) picks
/// the fit from them. Units: mm, kN, s, A (V for a voltage input).
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/names.h"
#include "core/progress.h"

namespace rths::ident {

/// The control filter between the record's command and the parameters' input (any input history).
enum class ControlFilter { kFirstOrder, kEq40, kNone };
inline constexpr std::array<Named<ControlFilter>, 3> kControlFilterNames = {
    {{ControlFilter::kFirstOrder, "first_order"}, {ControlFilter::kEq40, "eq40"}, {ControlFilter::kNone, "none"}}};

/// The control input of the fit with any input history.
enum class DamperInput {
  kAuto,     ///< the current if the first record has an i_A column, else the voltage
  kCurrent,  ///< the records' i_A [A]
  kVoltage,  ///< the records' v_V [V]
};

/// Options of the damper fits; defaults are those of `rths identify --damper`.
struct DamperFitOptions {
  /// Set: the fit at this one current [A] (Eqs. 32-34, FitDamper), >= 0; unset: the
  /// current- or voltage-dependent fit (Eqs. 32-39 with the control filter, FitSpencer).
  std::optional<double> current_A;
  double A = 300.0;                  ///< Bouc-Wen A, held fixed (scale redundancy, damper_fit.h), > 0
  double velocity_cutoff_hz = 0.0;   ///< SmoothVelocity cut-off [Hz], >= 0; 0 = VelocityCutoffHz per record
  /// Levenberg-Marquardt iterations per start, >= 1; unset: the fit's own (6 at one current; 8
  /// with any input, on a quarter of the data).
  std::optional<int> start_iterations;
  /// ... for the best start, >= 1; unset: the fit's own (200 at one current; 150 with any input).
  std::optional<int> max_iterations;
  /// Parameters held at a value, not fitted (`--hold name=value`): a model-file name the fit has
  /// ("alpha", "k0" at one current; "alpha_c", "c0_b", "eta_1_s", ... with any input) and a value
  /// > 0 inside the fit's range for it (the fit checks both and throws rths::Error naming them).
  std::vector<std::pair<std::string, double>> hold;

  // --- at one current
  /// Largest |i_k - current_A| [A] accepted in a record (the fit is at one current), >= 0.
  double current_tolerance_A = 0.05;

  // --- with any input history
  DamperInput input = DamperInput::kAuto;
  ControlFilter filter = ControlFilter::kFirstOrder;
  double eta_start_1_s = 100.0;     ///< first-order filter: eta of the starts [1/s], > 0
  bool accumulator = true;          ///< fit k1 and x0, or a force offset (LinearTerms); false: none
  int threads = 0;                  ///< Jacobian threads, >= 0; 0 = the machine's cores
  /// Progress in LM iterations on the whole record (a start's iteration on a quarter counts a
  /// quarter; the final fit counts max_iterations until it converges): empty = none.
  ProgressFn progress;

  /// True if every field is in range; else false and a message naming the field in *error (if not null).
  bool IsValid(std::string* error) const;
};

/// `--hold NAME=VALUE` -> (NAME, VALUE); throws rths::Error (where "--hold") unless NAME is not
/// empty and VALUE a finite number > 0.
std::pair<std::string, double> ParseHold(const std::string& text);

/// The box index of a held parameter among `names` (the fit's parameters in theta order), or
/// throws rths::Error (where "--hold") naming the parameter and the ones the fit has, or the
/// range [lo, hi] (natural units) its value must lie in.
int HeldIndex(const std::pair<std::string, double>& hold, const std::vector<std::string>& names,
              const std::vector<double>& lo, const std::vector<double>& hi);

}  // namespace rths::ident
