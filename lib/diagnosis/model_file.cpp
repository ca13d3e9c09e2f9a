#include "diagnosis/model_file.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rths::diagnosis {

scenario::Scenario FittedScenario(const NominalModel& model, const Result& r) {
  scenario::Scenario s;
  s.path = "";
  s.run.name = "diagnosed_model";
  if (r.dt_s > 0.0) s.run.dt_s = r.dt_s;
  s.plant.kind = models::PlantKind::kLinear;
  s.plant.actuator = model.actuator;
  s.controller.model = model.actuator;  // the controller is designed on the nominal actuator
  s.plant.specimen = model.has_damper ? models::Specimen::kMrDamper : models::Specimen::kNone;
  s.plant.damper = model.damper;
  s.plant.current_dynamics = model.current_dynamics;
  s.plant.current_driver = model.current_driver;
  for (const auto& e : r.effects) {
    if (e.selected) SetEffect(&s.plant.effects, e.name, e.params);
  }
  scenario::ValidateScenario(s);
  return s;
}

std::string FittedModelToml(const NominalModel& model, const Result& r) {
  const scenario::Scenario s = FittedScenario(model, r);
  std::string h = "# The diagnosed model (rths diagnose): the nominal model with the selected effects switched on\n";
  h += fmt::format("# nominal: {}\n", model.source);
  h += fmt::format("# training: {}\n# test: {}\n", fmt::join(r.train, ", "), fmt::join(r.test, ", "));
  h += fmt::format("# verdict: {}\n", fmt::join(r.verdict, ", "));
  for (const auto& c : r.channels) {
    if (c.diagnosed)
      h += fmt::format("# channel {}: test NRMSE {:.3f} % -> {:.3f} % ({})\n", c.channel, c.gap_test_pct,
                       c.after_test_pct, c.status);
  }
  h += "# Use: rths run THIS_FILE (rehearse a test on the diagnosed rig), rths design THIS_FILE,\n"
       "# or copy its [plant] tables into your scenario. The excitation and controller below are defaults.\n";
  return h + scenario::ToToml(s);
}

}  // namespace rths::diagnosis
