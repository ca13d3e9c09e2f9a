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
  const int dofs = integ.building.dofs();
  const int top = dofs - 1;
  r.floor = top + 1;
  std::vector<double> peak_drift(static_cast<std::size_t>(dofs), 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::vector<double>& x = log.desired[k].x_mm;
    if (x.size() != static_cast<std::size_t>(dofs))
      throw Error("structure response", fmt::format("step {} logged {} DOFs, the structure has {}", k, x.size(), dofs));
    for (int i = 0; i < dofs; ++i) {
      const double drift = x[static_cast<std::size_t>(i)] - (i > 0 ? x[static_cast<std::size_t>(i - 1)] : 0.0);
      peak_drift[static_cast<std::size_t>(i)] = std::max(peak_drift[static_cast<std::size_t>(i)], std::abs(drift));
    }
    r.peak_displacement_mm = std::max(r.peak_displacement_mm, std::abs(x[static_cast<std::size_t>(top)]));
    r.residual_displacement_mm = x[static_cast<std::size_t>(top)];
  }
  for (int i = 0; i < dofs; ++i) {
    const double d = peak_drift[static_cast<std::size_t>(i)];
    const double y = integ.building.springs[static_cast<std::size_t>(i)].YieldDisplacement();
    const double mu = y > 0 ? d / y : 0.0;
    if (mu > r.ductility || (r.ductility == 0.0 && d > r.peak_drift_mm)) r.story = i + 1, r.peak_drift_mm = d, r.ductility = mu;
  }
  if (state.x[top] != r.residual_displacement_mm)  // the replay is not the run: its energy would not be either
    throw Error("structure response", fmt::format("the replay ends at {} mm, the log at {} mm: the scenario is not "
                                                  "the run's", state.x[top], r.residual_displacement_mm));
  r.hysteretic_energy_kN_mm = state.building.HystereticEnergy();
  return r;
}

}  // namespace rths::participants
