#include "models/newmark_linear.h"

#include <cmath>

#include <Eigen/LU>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

NewmarkLinear MakeNewmarkLinear(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                const Eigen::MatrixXd& K, const Eigen::VectorXd& l, double dt_s,
                                double gamma, double beta) {
  const Eigen::Index n = M.rows();
  if (M.cols() != n || C.rows() != n || C.cols() != n || K.rows() != n || K.cols() != n ||
      l.size() != n || n == 0) {
    throw Error("Newmark", "M, C, K must be n x n and l n long, n > 0");
  }
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("Newmark", "dt_s must be > 0");
  if (!(gamma >= 0.5) || !(beta > 0.0)) throw Error("Newmark", "needs gamma >= 1/2 and beta > 0");
  NewmarkLinear m;
  m.M = M;
  m.C = C;
  m.dt_s = dt_s;
  m.a0 = 1.0 / beta / (dt_s * dt_s);
  m.a1 = gamma / beta / dt_s;
  m.a2 = 1.0 / beta / dt_s;
  m.a3 = 1.0 / 2.0 / beta - 1.0;
  m.a4 = gamma / beta - 1.0;
  m.a5 = dt_s / 2.0 * (gamma / beta - 2.0);
  m.a6 = dt_s * (1.0 - gamma);
  m.a7 = gamma * dt_s;
  const Eigen::MatrixXd Kbar = K + m.a0 * M + m.a1 * C;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(Kbar);
  if (!lu.isInvertible()) throw Error("Newmark", "K + a0 M + a1 C is singular");
  m.Kbar_inv = lu.inverse();
  m.Ml = M * l;
  return m;
}

NewmarkLinearState NewmarkLinearAtRest(const NewmarkLinear& m) {
  const Eigen::Index n = m.M.rows();
  NewmarkLinearState s;
  for (Eigen::VectorXd* v : {&s.U, &s.V, &s.A, &s.F, &s.work_m, &s.work_c, &s.rbar}) {
    v->setZero(n);
  }
  return s;
}

void NewmarkLinearStep(const NewmarkLinear& m, NewmarkLinearState* state, double ag) {
  NewmarkLinearState& s = *state;
  s.work_m = m.a0 * s.U + m.a2 * s.V + m.a3 * s.A;
  s.work_c = m.a1 * s.U + m.a4 * s.V + m.a5 * s.A;
  s.rbar.noalias() = m.M * s.work_m;
  s.rbar.noalias() += m.C * s.work_c;
  s.rbar -= s.F;
  s.rbar -= ag * m.Ml;
  // work_m: U1; then A1 into work_c; V and A last (they are the step's inputs above).
  s.work_m.noalias() = m.Kbar_inv * s.rbar;
  s.work_c = m.a0 * (s.work_m - s.U) - m.a2 * s.V - m.a3 * s.A;
  s.V += m.a7 * s.work_c + m.a6 * s.A;
  s.A = s.work_c;
  s.U = s.work_m;
}

}  // namespace rths::models
