#pragma once
/// @file The controller a scenario names, designed from its models and analysed, as one summary
/// that prints itself and serialises to JSON (`rths design`; docs/controllers.md).
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/analysis.h"
#include "control/baselines.h"
#include "control/inverse_lowpass.h"
#include "control/lqg.h"

namespace rths::control {

/// G_yr at one frequency (docs/experiments.md E2).
struct TrackingPoint {
  double f_hz = 0.0;
  double magnitude = 0.0;  ///< |G_yr| [-]
  double lag_ms = 0.0;     ///< -arg G_yr / w [ms]
};

/// The controller on one linear ZOH plant model.
struct PlantCheck {
  models::ServoModel3 model;
  double current_A = 0.0;              ///< current assumed for `bumpless_lp` (0 / 1.25 / 2.5 A)
  std::vector<TrackingPoint> tracking; ///< G_yr at 1 .. 50 Hz
  std::optional<LoopAnalysis> loop;    ///< feedback loop (ff_lqg only)
};

struct DesignSummary {
  control::ControllerConfig config;
  double dt_s = 0.0;
  std::optional<FeedforwardCoefficients> feedforward;  ///< ff, ff_lqg
  std::optional<Poly3Design> poly3;
  std::optional<LeadDesign> lead;
  std::vector<InverseLowpassDesign> lowpass;           ///< ff_lp: one; bumpless_lp: low, high
  std::optional<LqgDesign> lqg;
  std::vector<PlantCheck> plants;  ///< the design model (if not a preset), then 0.0A, avg, 2.5A

  /// Readable multi-line report.
  std::string Report() const;
  /// The same content as JSON (complex numbers as [re, im]).
  nlohmann::json ToJson() const;
};

/// Designs (as MakeTrackingController does, with the same errors) and analyses the controller.
DesignSummary DesignController(const control::ControllerConfig& cfg, double dt_s);

}  // namespace rths::control
