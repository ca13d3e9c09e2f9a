#include "models/structure_integrator.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

StructureIntegrator StructureIntegrator::Make(const NonlinearBuilding& b, double dt_s,
                                              const IntegratorConfig& c) {
  c.Validate();
  StructureIntegrator m;
  m.building = b;
  m.config = c;
  m.dt_s = dt_s;
  switch (c.kind) {
    case IntegratorKind::kCentralDifference:
      m.method = NonlinearCentralDifference::Make(b, dt_s, c.substeps);
      break;
    case IntegratorKind::kCr: m.method = ChenRicles::Make(b, dt_s, c.substeps); break;
    case IntegratorKind::kAlphaOs: m.method = AlphaOs::Make(b, dt_s, c.alpha); break;
    case IntegratorKind::kNewmarkImplicit:
      m.method = NewmarkImplicit::Make(b, dt_s, c.newton_iterations);
      break;
    case IntegratorKind::kRk4UnitDelay:
      throw Error("integrator", "rk4_unit_delay runs linear structures only (the benchmark's reference-code loop)");
  }
  return m;
}

void Advance(const StructureIntegrator& m, IntegratorState* s, double ag, double ag_next, double f) {
  std::visit(
      [&](const auto& method) {
        using T = std::decay_t<decltype(method)>;
        if constexpr (std::is_same_v<T, AlphaOs>)
          Advance(method, m.building, s, ag, f);
        else
          Advance(method, m.building, s, ag, ag_next, f);
      },
      m.method);
}

SimulatedRun Simulate(const StructureIntegrator& m, const std::vector<double>& ag,
                      const std::vector<double>& f) {
  const std::size_t n = ag.size();
  if (!f.empty() && f.size() != n)
    throw Error("Simulate", fmt::format("force history has {} samples, ground {}", f.size(), n));
  IntegratorState s = MakeIntegratorState(m.building);
  SimulatedRun run;
  run.x_mm.resize(m.building.dofs(), static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) {
    run.x_mm.col(static_cast<Eigen::Index>(k)) = s.x;
    Advance(m, &s, ag[k], ag[std::min(k + 1, n - 1)], f.empty() ? 0.0 : f[k]);
    run.max_residual_kN = std::max(run.max_residual_kN, s.residual_kN);
  }
  run.hysteretic_energy_kN_mm = s.building.HystereticEnergy();
  return run;
}

}  // namespace rths::models
