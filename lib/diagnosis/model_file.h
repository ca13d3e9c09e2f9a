#pragma once
/// @file The diagnosed model as a scenario file: the nominal model (its actuator, damper and
/// current dynamics) with the effects the diagnosis selected switched on as rig-mode effects
/// (`[plant.effects.<name>]`, docs/rig_mode.md). `rths run FILE` rehearses a test on it,
/// `rths design FILE` designs the scenario's controller on its nominal actuator, and
/// `rths diagnose --model FILE` takes its [plant] as the nominal model (the effects are not part
/// of a nominal model and are ignored there, with a note).
#include <string>

#include "diagnosis/channel_models.h"
#include "diagnosis/diagnosis.h"
#include "scenario/scenario.h"

namespace rths::diagnosis {

/// A runnable scenario (default excitation and controller of scenario::Scenario, the record's
/// step r.dt_s, plant.kind = "linear") whose plant is `model` plus every selected effect of `r`
/// with its fitted parameters. Validated; throws rths::Error if a fitted value lies outside a
/// scenario range.
scenario::Scenario FittedScenario(const NominalModel& model, const Result& r);

/// FittedScenario as TOML text, with a header saying where it came from (records, verdict and
/// each channel's test NRMSE before and after).
std::string FittedModelToml(const NominalModel& model, const Result& r);

}  // namespace rths::diagnosis
