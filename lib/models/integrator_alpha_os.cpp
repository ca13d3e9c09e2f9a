#include "models/integrator_alpha_os.h"

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

AlphaOs AlphaOs::Make(const NonlinearBuilding& b, double dt_s, double alpha) {
  if (!(alpha >= -1.0 / 3.0 && alpha <= 0.0))
    throw Error("alpha", fmt::format("must be in [-1/3, 0] (got {})", alpha));
  if (!(dt_s > 0.0)) throw Error("dt_s", fmt::format("must be > 0 (got {})", dt_s));
  AlphaOs m;
  m.alpha = alpha;
  m.beta = (1.0 - alpha) * (1.0 - alpha) / 4.0;
  m.gamma = 0.5 - alpha;
  m.dt_s = dt_s;
  m.m_inv = b.M.inverse();
  m.mhat_inv = (b.M + (1.0 + alpha) * (m.gamma * dt_s * b.C + m.beta * dt_s * dt_s * b.K0)).inverse();
  m.m_iota = b.M * b.iota;
  m.K0 = b.K0;
  return m;
}

void Advance(const AlphaOs& m, const NonlinearBuilding& b, IntegratorState* s, double ag, double f) {
  const double dt = m.dt_s, al = m.alpha;
  Evaluate(b, s->x, &s->building);  // R~_k at the predictor
  Commit(&s->building);
  // w1 = M iota a_g,k + s f_k + R~_k (the part of Q_k known before the corrector)
  s->w1 = ag * m.m_iota + f * b.specimen_dir + s->building.restoring_kN;
  if (!s->started) {  // k = 0: equilibrium at rest, x~_0 = x_0, v~_0 = v_0
    s->w2 = s->w1;
    s->w2.noalias() += b.C * s->v;
    s->a.noalias() = -m.m_inv * s->w2;
    s->x_corr = s->x;
    s->q_prev = s->w2;
    s->started = true;
  } else {
    s->w2 = s->w1;
    s->w2.noalias() += b.C * s->v_pred;
    s->w3 = al * s->q_prev - (1.0 + al) * s->w2;
    s->a.noalias() = m.mhat_inv * s->w3;
    s->x_corr = s->x + (m.beta * dt * dt) * s->a;
    s->v = s->v_pred + (m.gamma * dt) * s->a;
    // Q_k = w1 + C v_k + K0 (x_k - x~_k)
    s->q_prev = s->w1;
    s->q_prev.noalias() += b.C * s->v;
    s->w3 = s->x_corr - s->x;
    s->q_prev.noalias() += m.K0 * s->w3;
  }
  // Predictor of k + 1.
  s->x = s->x_corr + dt * s->v + ((0.5 - m.beta) * dt * dt) * s->a;
  s->v_pred = s->v + ((1.0 - m.gamma) * dt) * s->a;
  ++s->k;
}

}  // namespace rths::models
