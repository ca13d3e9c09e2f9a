#include "models/integrator_newmark.h"

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {
namespace {

// a(x), v(x) of the average-acceleration rule into s->a, s->v and the residual into s->w3, from
// x_k, v_k, a_k in x_prev, w1, w2, after Evaluate at s->x.
void Residual(const NewmarkImplicit& m, const NonlinearBuilding& b, IntegratorState* s, double ag1,
              double f) {
  const double dt = m.dt_s;
  s->a = (4.0 / (dt * dt)) * (s->x - s->x_prev) - (4.0 / dt) * s->w1 - s->w2;
  s->v = (2.0 / dt) * (s->x - s->x_prev) - s->w1;
  s->w3 = -ag1 * m.m_iota - f * b.specimen_dir - s->building.restoring_kN;
  s->w3.noalias() -= b.M * s->a;
  s->w3.noalias() -= b.C * s->v;
}

}  // namespace

NewmarkImplicit NewmarkImplicit::Make(const NonlinearBuilding& b, double dt_s, int iterations) {
  if (iterations < 1 || iterations > 100)
    throw Error("newton_iterations", fmt::format("must be in [1, 100] (got {})", iterations));
  if (!(dt_s > 0.0)) throw Error("dt_s", fmt::format("must be > 0 (got {})", dt_s));
  NewmarkImplicit m;
  m.dt_s = dt_s;
  m.iterations = iterations;
  m.m_inv = b.M.inverse();
  m.j_const = 4.0 / (dt_s * dt_s) * b.M + 2.0 / dt_s * b.C;
  m.m_iota = b.M * b.iota;
  return m;
}

void Advance(const NewmarkImplicit& m, const NonlinearBuilding& b, IntegratorState* s, double ag,
             double ag1, double f) {
  const double dt = m.dt_s;
  if (!s->started) {  // a_0 from the equilibrium at rest
    Evaluate(b, s->x, &s->building);
    Commit(&s->building);
    s->w3 = -ag * m.m_iota - f * b.specimen_dir - s->building.restoring_kN;
    s->w3.noalias() -= b.C * s->v;
    s->a.noalias() = m.m_inv * s->w3;
    s->started = true;
  }
  s->x_prev = s->x;  // x_k
  s->w1 = s->v;      // v_k
  s->w2 = s->a;      // a_k
  s->x += dt * s->w1 + (0.5 * dt * dt) * s->w2;
  for (int i = 0; i < m.iterations; ++i) {
    Evaluate(b, s->x, &s->building);
    Residual(m, b, s, ag1, f);
    AssembleTangent(b, s->building, &s->J);
    s->J += m.j_const;
    s->lu.compute(s->J);
    s->w4 = s->lu.solve(s->w3);
    s->x += s->w4;
  }
  Evaluate(b, s->x, &s->building);
  Residual(m, b, s, ag1, f);
  s->residual_kN = s->w3.norm();
  Commit(&s->building);
  ++s->k;
}

}  // namespace rths::models
