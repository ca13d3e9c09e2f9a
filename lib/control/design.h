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
#include "control/lti_controller.h"

namespace rths::control {

/// G_yr at one frequency (docs/experiments.md E2).
struct TrackingPoint {
  double f_hz = 0.0;
  double magnitude = 0.0;  ///< |G_yr| [-]
  double lag_ms = 0.0;     ///< -arg G_yr / w [ms]
};

/// The controller on one linear ZOH plant model.
struct PlantCheck {
  std::string name;                    ///< the servo model's name ("0.0A", "custom") or the plant's
  std::optional<models::ServoModel3> model;  ///< the servo model, if the plant is one
  double current_A = 0.0;              ///< current assumed for `bumpless_lp` (0 / 1.25 / 2.5 A)
  std::vector<TrackingPoint> tracking; ///< G_yr at 1 .. 50 Hz
  std::optional<LoopAnalysis> loop;    ///< feedback loop (ff_lqg, lti)
};

/// A plant to analyse the design on, other than the paper's servo models (e.g. the scenario's
/// benchmark plant Gp): u [mm] -> y [mm], discrete at the design's dt.
struct DesignPlant {
  std::string name;
  DiscreteSs g;
};

struct DesignSummary {
  control::ControllerConfig config;
  double dt_s = 0.0;
  std::optional<FeedforwardCoefficients> feedforward;  ///< ff, ff_lqg
  std::optional<Poly3Design> poly3;
  std::optional<LeadDesign> lead;
  std::vector<InverseLowpassDesign> lowpass;           ///< ff_lp: one; bumpless_lp: low, high
  std::optional<LqgDesign> lqg;
  std::optional<LtiDesign> lti;
  /// The design model (if not a preset), then the given plants, or 0.0A, avg, 2.5A if none is given.
  std::vector<PlantCheck> plants;

  /// Readable multi-line report.
  std::string Report() const;
  /// The same content as JSON (complex numbers as [re, im]).
  nlohmann::json ToJson() const;
};

/// Designs (as MakeTrackingController does, with the same errors) and analyses the controller on
/// the design model (a "custom" controller.model), then on `plants`, or on the paper's three servo
/// models (0.0 A, avg, 2.5 A) when `plants` is empty.
DesignSummary DesignController(const control::ControllerConfig& cfg, double dt_s,
                               const std::vector<DesignPlant>& plants = {});

}  // namespace rths::control
