#include "models/structure.h"

#include <cmath>
#include <numbers>
#include <utility>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

LinearStructure LinearStructure::Sdof(double mass_kg, double frequency_hz, double damping_ratio,
                                      double specimen_count) {
  if (!(mass_kg > 0.0) || !std::isfinite(mass_kg))
    throw Error("LinearStructure: mass_kg", fmt::format("must be > 0 (got {})", mass_kg));
  if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz))
    throw Error("LinearStructure: frequency_hz", fmt::format("must be > 0 (got {})", frequency_hz));
  if (!(damping_ratio >= 0.0 && damping_ratio < 1.0))
    throw Error("LinearStructure: damping_ratio",
                fmt::format("must be in [0, 1) (got {})", damping_ratio));
  const double m = mass_kg * 1e-6;  // kN s^2/mm
  const double w = 2.0 * std::numbers::pi * frequency_hz;
  const auto scalar = [](double v) { return Eigen::MatrixXd::Constant(1, 1, v); };
  return Make(scalar(m), scalar(2.0 * damping_ratio * m * w), scalar(m * w * w), 0, specimen_count);
}

LinearStructure LinearStructure::Make(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                      const Eigen::MatrixXd& K, int actuator_dof,
                                      double specimen_count) {
  const Eigen::Index n = M.rows();
  if (n == 0 || M.cols() != n || C.rows() != n || C.cols() != n || K.rows() != n || K.cols() != n)
    throw Error("LinearStructure",
                fmt::format("M, C, K must be square and of one size (got "
                            "{}x{}, {}x{}, {}x{})",
                            M.rows(), M.cols(), C.rows(), C.cols(), K.rows(), K.cols()));
  if (!M.allFinite() || !C.allFinite() || !K.allFinite())
    throw Error("LinearStructure", "M, C, K must be finite");
  const auto symmetric = [](const Eigen::MatrixXd& A) {
    return (A - A.transpose()).norm() <= 1e-9 * A.norm();
  };
  if (!symmetric(M) || M.llt().info() != Eigen::Success)
    throw Error("LinearStructure: M", "must be symmetric positive definite");
  if (!symmetric(K)) throw Error("LinearStructure: K", "must be symmetric");
  if (actuator_dof < 0 || actuator_dof >= n)
    throw Error("LinearStructure: actuator_dof",
                fmt::format("must be in [0, {}] (got {})", n - 1, actuator_dof));
  if (!(specimen_count >= 0.0) || !std::isfinite(specimen_count))
    throw Error("LinearStructure: specimen_count",
                fmt::format("must be >= 0 (got {}; 0: the measured force does not act)", specimen_count));
  LinearStructure s;
  s.M = M, s.C = C, s.K = K;
  s.iota = Eigen::VectorXd::Ones(n);
  s.specimen_dir = Eigen::VectorXd::Zero(n);
  s.specimen_dir(actuator_dof) = specimen_count;
  s.actuator_dof = actuator_dof;
  return s;
}

CentralDifference CentralDifference::Make(const LinearStructure& s, double dt,
                                          bool enforce_stability_limit) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw Error("CentralDifference", fmt::format("dt_s must be > 0 (got {})", dt));
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.K, s.M,
                                                                      Eigen::EigenvaluesOnly);
  const double w_max = std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
  CentralDifference cd;
  cd.dt_s = dt;
  cd.max_frequency_hz = w_max / (2.0 * std::numbers::pi);
  cd.dt_limit_s = w_max > 0.0 ? 2.0 / w_max : INFINITY;  // T_min / pi
  if (enforce_stability_limit && dt >= cd.dt_limit_s)
    throw Error("CentralDifference",
                fmt::format("dt = {} s is at or above the stability limit T_min/pi = {:.6g} s "
                            "(highest natural frequency {:.6g} Hz)",
                            dt, cd.dt_limit_s, cd.max_frequency_hz));
  const Eigen::MatrixXd m_dt2 = s.M / (dt * dt), c_2dt = s.C / (2.0 * dt);
  const Eigen::PartialPivLU<Eigen::MatrixXd> khat(m_dt2 + c_2dt);
  cd.P_x = khat.solve(2.0 * m_dt2 - s.K);
  cd.P_xprev = -khat.solve(m_dt2 - c_2dt);
  cd.p_ground = -khat.solve(s.M * s.iota);
  cd.p_force = -khat.solve(s.specimen_dir);
  cd.iota = s.iota;
  cd.M = s.M, cd.C = s.C, cd.K = s.K;
  return cd;
}

StructureState MakeState(const CentralDifference& cd) {
  const Eigen::Index n = cd.dofs();
  StructureState s;
  s.x_prev = s.x = s.vel_prev = s.acc_prev = s.abs_acc_prev = s.x_next = Eigen::VectorXd::Zero(n);
  return s;
}

void SetInitialConditions(const CentralDifference& cd, StructureState* s, const Eigen::VectorXd& x0,
                          const Eigen::VectorXd& v0) {
  if (x0.size() != cd.dofs() || v0.size() != cd.dofs())
    throw Error("SetInitialConditions", fmt::format("x0, v0 must have {} entries", cd.dofs()));
  const Eigen::VectorXd a0 = cd.M.llt().solve(-cd.C * v0 - cd.K * x0);
  s->k = 0;
  s->x = x0;
  s->x_prev = x0 - cd.dt_s * v0 + 0.5 * cd.dt_s * cd.dt_s * a0;
}

void Advance(const CentralDifference& cd, StructureState* s, double ground_acc_mm_s2,
             double specimen_force_kN) {
  const double dt = cd.dt_s;
  s->x_next.noalias() = cd.P_x * s->x;
  s->x_next.noalias() += cd.P_xprev * s->x_prev;
  s->x_next += cd.p_ground * ground_acc_mm_s2 + cd.p_force * specimen_force_kN;
  s->vel_prev = (s->x_next - s->x_prev) / (2.0 * dt);              // Eq. 2 at k
  s->acc_prev = (s->x_next - 2.0 * s->x + s->x_prev) / (dt * dt);  // Eq. 3 at k
  s->abs_acc_prev = s->acc_prev + cd.iota * ground_acc_mm_s2;
  std::swap(s->x_prev, s->x);  // x_prev = x_k
  std::swap(s->x, s->x_next);  // x = x_{k+1}
  ++s->k;
}

}  // namespace rths::models
