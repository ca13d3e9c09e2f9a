#pragma once
/// @file The servohydraulic actuator's identification from one record of command u and measured
/// y (`rths identify`, docs/identification.md "Two fits"): the two fits of Eq. 15, their report,
/// their model file and their Bode figure (like the paper's Fig. 6). Shaped like the damper's
/// DamperModelFit (damper_model.h): FitActuator(...) -> ActuatorFit {Report, ModelToml, Bode}.
#include <span>
#include <string>
#include <vector>

#include "ident/identify.h"
#include "io/bode_figure.h"
#include "io/plot.h"
#include "signal/bode.h"

namespace rths::ident {

/// A model's response on the grid f_hz [Hz] (> 0) as a Bode curve (signal/bode.h): continuous if
/// zoh_dt_s = 0, else that of its zero-order-hold discretisation at zoh_dt_s [s] (what a ZOH
/// plant sampled at the same rate shows).
signal::BodeCurve BodeFromModel(const std::string& name, const PoleModel& model, const std::vector<double>& f_hz,
                                double zoh_dt_s);

/// The two fits of one record.
struct ActuatorFit {
  /// Eq. 15 fitted to the measured G_yu as the paper does (the D/A hold's half-sample lag
  /// included): a design model, the model file's [controller] model.
  IdentifyResult continuous;
  /// The continuous model whose ZOH discretisation at the record's dt matches the measured
  /// response: a plant to simulate, the model file's [plant] actuator.
  IdentifyResult zoh;

  /// What `rths identify` prints: the continuous fit's report (IdentifyResult::Report), then the
  /// ZOH-consistent fit's and its time-domain Eq. 31 error [%].
  std::string Report() const;
  /// The model file (ScenarioFragment of the two fits); `title` is its first comment line.
  std::string ModelToml(const std::string& title) const;
  /// Fig. 6 style, 0 to min(50 Hz, Nyquist): magnitude [mm/mm], phase [deg], time lag [ms] and
  /// coherence [-] against frequency; the measured H1 at its excited points beside the continuous
  /// fit and the ZOH-consistent fit's discrete response on a 500-point grid; the fitted band
  /// shaded; one legend beside the magnitude panel.
  io::Figure Bode(const std::string& title) const;
};

/// Both fits of u, y [mm] at step dt_s [s] with `options` (options.fit.zoh_dt_s is not used: the
/// continuous fit has 0, the ZOH-consistent one dt_s). Throws what Identify throws.
ActuatorFit FitActuator(std::span<const double> u_mm, std::span<const double> y_mm, double dt_s,
                        const IdentifyOptions& options);

}  // namespace rths::ident
