#include "participants/structure_response.h"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "models/structure_file.h"
#include "signal/history.h"

namespace rths::participants {

StructureResponse StructureResponseOfRun(const io::RunLog& log, const scenario::Scenario& s) {
  if (!s.structure.Stepped()) throw Error("structure response", "the run's structure is not a stepped one");
  const std::int64_t steps = log.CompleteSteps();
  if (steps < 1) throw Error("structure response", "the log has no complete step");
  const auto n = static_cast<std::size_t>(steps);
  const models::StructureIntegrator integ = models::SteppedIntegratorFromScenario(s.structure, s.run.dt_s);
  // The integrator's inputs as it had them: a_g,k of the scenario's record, f_k as logged.
  const std::vector<double> ground = signal::MakeSignal(s.structure.ground, s.run.dt_s, n);
  // Step k as models::Step takes it (numerical_substructure.h): x_k from a_g,k-1, a_g,k, f_k-1.
  models::IntegratorState state = models::MakeIntegratorState(integ.building);
  for (std::size_t k = 1; k < n; ++k) models::Advance(integ, &state, ground[k - 1], ground[k], log.measured[k - 1].f_kN);
  StructureResponse r;
  const int top = integ.building.dofs() - 1;
  r.floor = top + 1;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = log.desired[k].x_mm[static_cast<std::size_t>(top)];
    r.peak_displacement_mm = std::max(r.peak_displacement_mm, std::abs(x));
    r.residual_displacement_mm = x;
  }
  if (state.x[top] != r.residual_displacement_mm)  // the replay is not the run: its energy would not be either
    throw Error("structure response", fmt::format("the replay ends at {} mm, the log at {} mm: the scenario is not "
                                                  "the run's", state.x[top], r.residual_displacement_mm));
  r.hysteretic_energy_kN_mm = state.building.HystereticEnergy();
  r.yield_displacement_mm = integ.building.springs[static_cast<std::size_t>(top)].YieldDisplacement();
  return r;
}

}  // namespace rths::participants
