#include "models/integrator_cd.h"

#include <utility>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

NonlinearCentralDifference NonlinearCentralDifference::Make(const NonlinearBuilding& b, double dt_s,
                                                            int substeps) {
  if (substeps < 1 || substeps > 1000)
    throw Error("substeps", fmt::format("must be in [1, 1000] (got {})", substeps));
  if (!(dt_s > 0.0)) throw Error("dt_s", fmt::format("must be > 0 (got {})", dt_s));
  const double h = dt_s / substeps;
  NonlinearCentralDifference m;
  m.linear = CentralDifference::Make(b.Initial(), h);
  m.khat_inv = (b.M / (h * h) + b.C / (2.0 * h)).inverse();
  m.K0 = b.K0;
  m.substeps = substeps;
  m.dt_s = dt_s;
  m.all_linear = b.all_linear;
  return m;
}

void Advance(const NonlinearCentralDifference& m, const NonlinearBuilding& b, IntegratorState* s,
             double ag, double ag_next, double f) {
  const CentralDifference& cd = m.linear;
  const double h = cd.dt_s;
  for (int j = 0; j < m.substeps; ++j) {
    const double ag_j = j == 0 ? ag : ag + (ag_next - ag) * (static_cast<double>(j) / m.substeps);
    // Today's recurrence, operation for operation (models::Advance).
    s->w1.noalias() = cd.P_x * s->x;
    s->w1.noalias() += cd.P_xprev * s->x_prev;
    s->w1 += cd.p_ground * ag_j + cd.p_force * f;
    if (!m.all_linear) {
      Evaluate(b, s->x, &s->building);
      Commit(&s->building);
      s->w2.noalias() = m.K0 * s->x;
      s->w2 -= s->building.restoring_kN;
      s->w1.noalias() += m.khat_inv * s->w2;
    }
    s->v = (s->w1 - s->x_prev) / (2.0 * h);
    s->a = (s->w1 - 2.0 * s->x + s->x_prev) / (h * h);
    std::swap(s->x_prev, s->x);
    std::swap(s->x, s->w1);
  }
  ++s->k;
}

}  // namespace rths::models
