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
#include "ident/measurement_fit.h"
#include "ident/spencer_fit.h"
#include "io/rig_record.h"

namespace rths::ident {

/// A fitted damper model: exactly one of the two results is set.
struct DamperModelFit {
  std::optional<DamperFitResult> at_current;  ///< the fit at one current
  std::optional<SpencerFitResult> any_input;  ///< the fit with any input history
  double velocity_cutoff_hz = 0.0;            ///< the options' cut-off [Hz]; 0 = VelocityCutoffHz per record
  /// The force channel's skew and the load cell's inertia (measurement_fit.h), if asked for: the
  /// damper model is then fitted to the damper's own force they imply, and predicts the
  /// measured force through them.
  MeasurementFit measurement;

  /// The input is a voltage (any input history with v_V).
  bool voltage() const { return any_input && any_input->voltage; }
  /// How the fit ended (ident/fit_status.h).
  const FitStatus& status() const;
  /// What to try (ident/fit_advice.h): a line per parameter on a bound or implausible, and for a
  /// fit that failed; empty for a fit that is ok and plausible.
  std::vector<std::string> Advice() const;
  /// The result's Report() (coefficients, derived quantities, the status, per-record errors).
  std::string Report() const;
  /// The velocity cut-off [Hz] used on a record: the options' or VelocityCutoffHz(record).
  double CutoffHz(const io::RigRecord& record) const;
  /// The damper's force F_k [kN] on a record's motion (and command), with the velocity smoothed at
  /// CutoffHz (and the load cell's zero when fitted), before the measurement's effects.
  std::vector<double> DamperForce(const io::RigRecord& record) const;
  /// The measured force the model predicts [kN]: DamperForce through the measurement's effects.
  std::vector<double> PredictForce(const io::RigRecord& record) const;
  /// Eq. 31 on force of the model on a record (held-out check).
  DamperRecordScore Score(const io::RigRecord& record) const;
  /// The model as a TOML file (DamperTomlFragment or SpencerModelToml) with `title` in its first comment.
  std::string ModelToml(const std::string& title) const;
  /// The held-out check `rths identify --damper --check` prints: a heading, then a line per record
  /// with its samples, step [s], peak force [kN] and Score [%], or where the prediction stops
  /// being finite (the model too stiff for the record's motion, or diverging); "" for no records.
  std::string HeldOutReport(const std::vector<io::RigRecord>& held) const;

  /// What a tool says after the model file, and the exit code it returns (the exit rule of
  /// ident/fit_status.h).
  struct Verdict {
    std::string messages;  ///< lines for stderr, each starting "`tool`: ": warnings, what to try, the status
    int exit_code = 0;     ///< 0, or kExitFitFailed for a fit that failed unless accepted
  };
  /// The implausible values (warnings), what to try (Advice), and for a fit that failed its
  /// status and exit code: kExitFitFailed, or 0 with `accept_unconverged` (--accept-unconverged).
  Verdict Judge(const std::string& tool, bool accept_unconverged) const;
};

/// Fits the damper model options ask for (options.current_A set: FitDamper; else FitSpencer) to
/// the records. With measurement effects asked for (measurement.Any()): the model is fitted, the
/// skew and mass are fitted around it (FitMeasurement), the model is fitted again to the damper's
/// own force they imply (MeasurementFit::DamperForceRecord), and the skew and mass again around
/// that model; the training scores are those of the measured force. Throws rths::Error as those do.
DamperModelFit FitDamperModel(const std::vector<io::RigRecord>& records, const DamperFitOptions& options,
                              const MeasurementOptions& measurement = {});

}  // namespace rths::ident
