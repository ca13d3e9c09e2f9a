#pragma once
/// @file One front for the MR damper fits (`rths identify --damper`, docs/identification.md "The
/// MR damper"): FitDamperModel runs the fit its options ask for, at one current (FitDamper,
/// Eqs. 32-34) or with any input history (FitSpencer, Eqs. 32-39 with the control filter), and the
/// result answers the same questions whichever it is: its report, its force on a record, its
/// score on a held-out record, its model file. Units: mm, kN, s, A (V for a voltage input).
#include <optional>
#include <string>
#include <vector>

#include "ident/damper_fit.h"
#include "ident/damper_options.h"
#include "ident/spencer_fit.h"
#include "io/rig_record.h"

namespace rths::ident {

/// A fitted damper model: exactly one of the two results is set.
struct DamperModelFit {
  std::optional<DamperFitResult> at_current;  ///< the fit at one current
  std::optional<SpencerFitResult> any_input;  ///< the fit with any input history
  double velocity_cutoff_hz = 0.0;            ///< the options' cut-off [Hz]; 0 = VelocityCutoffHz per record

  /// The input is a voltage (any input history with v_V).
  bool voltage() const { return any_input && any_input->voltage; }
  /// How the fit ended (ident/fit_status.h).
  const FitStatus& status() const;
  /// The result's Report() (coefficients, derived quantities, the status, per-record errors).
  std::string Report() const;
  /// The velocity cut-off [Hz] used on a record: the options' or VelocityCutoffHz(record).
  double CutoffHz(const io::RigRecord& record) const;
  /// The model's force F_k [kN] on a record's motion (and command), with the velocity smoothed at CutoffHz.
  std::vector<double> PredictForce(const io::RigRecord& record) const;
  /// Eq. 31 on force of the model on a record (held-out check).
  DamperRecordScore Score(const io::RigRecord& record) const;
  /// The model as a TOML file (DamperTomlFragment or SpencerModelToml) with `title` in its first comment.
  std::string ModelToml(const std::string& title) const;
};

/// Fits the damper model options ask for (options.current_A set: FitDamper; else FitSpencer) to
/// the records. Throws rths::Error as those do.
DamperModelFit FitDamperModel(const std::vector<io::RigRecord>& records, const DamperFitOptions& options);

}  // namespace rths::ident
