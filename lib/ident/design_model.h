#pragma once
/// @file The model a model-based tracking controller is designed on, made to follow the plant the
/// scenario drives (issue 43: a benchmark scenario with controller.kind = "ff_lqg" was designed on
/// the paper's damper-rig servo model, 9 ms of lag, where the benchmark plant has 25 ms).
#include <array>
#include <functional>
#include <string>

#include "ident/identify.h"
#include "models/marths_plant.h"
#include "scenario/scenario.h"

namespace rths::ident {

/// The third-order design fit of a plant rths can simulate, as `rths reproduce benchmark`
/// identifies one: ident::Identify (3 poles over 0.5-25 Hz, the hold's half-sample lag in the
/// fit) on a noise-free 20 s BLWN command (0-30 Hz, 1 mm RMS, seed 11) through the plant.
/// `plant(u_k)` returns y_k [mm] (the reading before u_k is applied) and then holds u_k [mm]
/// over the next step. Deterministic.
FitSummary FitDesignModel(const std::function<double(double u_mm)>& plant, double dt_s);

/// Sets the design model of a model-based controller (ff, ff_lp, ff_lqg, ambc started from the
/// model) to the plant's own where the scenario leaves it at the default, and says which model the
/// design uses:
///   - plant.kind = "benchmark" and controller.model the paper's "avg" (its default): the model
///     becomes a third-order fit of the benchmark's Gp, as `rths reproduce benchmark` identifies it
///     (ident::Identify, 3 poles over 0.5-25 Hz, the hold's half-sample lag included) but on a
///     noise-free 20 s BLWN record (0-30 Hz, 1 mm RMS, seed 11) through Gp itself, no run needed;
///   - plant.kind = "benchmark" and another preset ("0.0A", "2.5A"): kept, with a warning that the
///     design is on the paper's damper rig, not on the plant driven;
///   - plant.kind = "linear" with an identified actuator (plant.actuator custom, e.g. the fragment
///     `rths identify --out` writes) and controller.model "avg": the model becomes plant.actuator;
///     another preset is kept, with a warning naming both (a custom controller.model, such as the
///     continuous fit `rths identify --out` writes beside the plant's ZOH fit, is the user's choice);
///   - otherwise (the damper rig's presets, a custom model): kept.
/// Returns the line to print ("controller: designed on ..."); empty for a controller that uses no
/// model. Deterministic: the same scenario gives the same model, bit for bit.
///
/// With marths.enabled (docs/marths.md): for ff and ff_lqg, marths.model_1 and model_2 left at "avg"
/// become MarthsDesignModels of the nominal plant (the design plant also of a perturbed run).
std::string ResolveDesignModel(scenario::Scenario* s);

/// The third-order design models of the diagonal elements H_11, H_22 of the maRTHS plant `p` at
/// step dt_s: FitDesignModel on the plant driven through one actuator, the other held at 0.
std::array<models::ServoModel3, 2> MarthsDesignModels(const models::marths::PlantZpk& p, double dt_s);

}  // namespace rths::ident
