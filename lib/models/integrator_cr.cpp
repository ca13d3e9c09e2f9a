#include "models/integrator_cr.h"

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

ChenRicles ChenRicles::Make(const NonlinearBuilding& b, double dt_s, int substeps) {
  if (substeps < 1 || substeps > 1000)
    throw Error("substeps", fmt::format("must be in [1, 1000] (got {})", substeps));
  if (!(dt_s > 0.0)) throw Error("dt_s", fmt::format("must be > 0 (got {})", dt_s));
  const double h = dt_s / substeps;
  ChenRicles m;
  const Eigen::MatrixXd alpha =
      4.0 * (4.0 * b.M + 2.0 * h * b.C + h * h * b.K0).partialPivLu().solve(b.M);
  m.m_inv = b.M.inverse();
  m.h_alpha = h * alpha;
  m.h2_alpha = h * h * alpha;
  m.m_iota = b.M * b.iota;
  m.substeps = substeps;
  m.dt_s = dt_s;
  return m;
}

void Advance(const ChenRicles& m, const NonlinearBuilding& b, IntegratorState* s, double ag,
             double ag_next, double f) {
  const double h = m.dt_s / m.substeps;
  for (int j = 0; j < m.substeps; ++j) {
    const double ag_j = j == 0 ? ag : ag + (ag_next - ag) * (static_cast<double>(j) / m.substeps);
    Evaluate(b, s->x, &s->building);
    Commit(&s->building);
    s->w1 = -ag_j * m.m_iota - f * b.specimen_dir - s->building.restoring_kN;
    s->w1.noalias() -= b.C * s->v;
    s->a.noalias() = m.m_inv * s->w1;
    s->x += h * s->v;
    s->x.noalias() += m.h2_alpha * s->a;
    s->v.noalias() += m.h_alpha * s->a;
  }
  ++s->k;
}

}  // namespace rths::models
