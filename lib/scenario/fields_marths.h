#pragma once
/// @file Internal to lib/scenario: the schema of [marths] (control/marths_config.h), walked by the
/// visitors of fields.h (Reader, Writer, Checker): every key once, in file order, with its range.
#include "control/marths_config.h"
#include "scenario/ranges.h"

namespace rths::scenario::detail {

template <typename V>
void MarthsFields(V& v, control::MarthsConfig& m, const Context&) {
  v.Bool("enabled", m.enabled);
  v.String("reference_k_file", m.reference_k_file);  // ValidateMarths: given and present when enabled
  v.String("reference_m_file", m.reference_m_file);
  v.String("rodeac_file", m.rodeac_file);
  v.String("ground_file", m.ground_file);
  v.Number("ground_scale", m.ground_scale, OpenClosed(0.0, 100.0));
  v.Number("ideal_density_kg_m3", m.ideal_density_kg_m3, OpenClosed(0.0, 1e9));
  // The DOFs against the matrices' size and each other: ReadMarthsFiles (FrameDofsProblem).
  v.Numbers("interface_dofs", m.dofs.interface, Closed(1.0, 1e6));
  v.Numbers("story_dofs", m.dofs.stories, Closed(1.0, 1e6));
  v.Numbers("ground_dofs", m.dofs.ground, Closed(1.0, 1e6));
  v.Choice("compensator", m.compensator, control::kMarthsCompensatorNames);
  v.Integer("perturbed_plant", m.perturbed_plant, Closed(0, 10000));
  v.Integer("plant_seed", m.plant_seed, Closed(0.0, 9007199254740992.0));
  v.Integer("noise_seed", m.noise_seed, Closed(0.0, 9007199254740992.0));
  v.Bool("identical_noise", m.identical_noise);
  v.Numbers("coupler_xv_m", m.coupler.xv_m, Closed(-10.0, 10.0));  // the arms: ValidateMarths (CouplerProblem)
  v.Numbers("coupler_yv_m", m.coupler.yv_m, Closed(-10.0, 10.0));
  v.Numbers("coupler_alpha_deg", m.coupler.alpha_deg, Closed(-180.0, 180.0));
  v.Choice("inverse", m.inverse, control::kMarthsInverseNames);
  v.Integer("force_delay_steps", m.force_delay_steps, Closed(0, 1));
  v.Bool("derivatives_from_rest", m.derivatives_from_rest);
  v.Servo("model_1", m.model_1);
  v.Servo("model_2", m.model_2);
}

}  // namespace rths::scenario::detail
