#include "control/clipped_optimal.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "control/dare.h"
#include "control/lti.h"
#include "core/error.h"

namespace rths::control {

namespace {
constexpr double kG_mm_s2 = 9806.65;  // standard gravity [mm/s^2]
}

ClippedOptimalDesign DesignClippedOptimal(const models::LinearStructure& st, double dt_s,
                                          const ClippedOptimalOptions& o) {
  if (!(o.r_weight > 0) || !(o.noise_ratio > 0) || !(o.capacity_kN > 0) || !(o.max_current_A > 0)) {
    throw Error("semiactive", "clipped-optimal weights, noise ratio, capacity and current must be > 0");
  }
  const int n = st.dofs();
  const Eigen::MatrixXd Minv = st.M.inverse();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -Minv * st.K;
  A.bottomRightCorner(n, n) = -Minv * st.C;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(2 * n, 1);
  B.bottomRows(n) = -Minv * st.specimen_dir;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(2 * n, 1);
  E.bottomRows(n) = -st.iota;

  ClippedOptimalDesign d;
  d.n = n;
  d.options = o;
  d.Ca = A.bottomRows(n);
  d.Da = B.bottomRows(n).col(0);
  ZohDiscretise(A, B, dt_s, &d.Phi, &d.Gamma);

  // Regulator: J = sum (a^T a / g^2 + r (f / capacity)^2) dt, cross term kept.
  const double g2 = kG_mm_s2 * kG_mm_s2;
  const Eigen::MatrixXd Q = d.Ca.transpose() * d.Ca / g2 * dt_s;
  const Eigen::MatrixXd N = d.Ca.transpose() * d.Da / g2 * dt_s;
  const double R = (d.Da.squaredNorm() / g2 + o.r_weight / (o.capacity_kN * o.capacity_kN)) * dt_s;
  const Eigen::MatrixXd Ar = d.Phi - d.Gamma * (N.transpose() / R);
  Eigen::MatrixXd Qr = Q - N * N.transpose() / R;
  Qr = 0.5 * (Qr + Qr.transpose()).eval();
  const DareSolution lqr = SolveDare(Ar, d.Gamma, Qr, Eigen::MatrixXd::Constant(1, 1, R),
                                     "semiactive: clipped-optimal LQR");
  d.K = lqr.K.row(0) + N.transpose() / R;
  d.regulator_poles = (d.Phi - d.Gamma * d.K).eigenvalues();

  // Kalman filter: ground acceleration as process noise, one noise per acceleration sensor.
  const Eigen::MatrixXd Qd = VanLoanCovariance(A, E * E.transpose() * o.noise_ratio, dt_s);
  const Eigen::MatrixXd V = Eigen::MatrixXd::Identity(n, n) / dt_s;
  const DareSolution kf =
      SolveDare(d.Phi.transpose(), d.Ca.transpose(), Qd, V, "semiactive: clipped-optimal Kalman filter");
  const Eigen::MatrixXd& S = kf.X;
  d.L = S * d.Ca.transpose() * (d.Ca * S * d.Ca.transpose() + V).inverse();
  d.estimator_poles = (d.Phi - d.Phi * d.L * d.Ca).eigenvalues();
  for (const auto& p : d.regulator_poles) {
    if (std::abs(p) >= 1.0) throw Error("semiactive", "clipped-optimal regulator is not stable");
  }
  for (const auto& p : d.estimator_poles) {
    if (std::abs(p) >= 1.0) throw Error("semiactive", "clipped-optimal estimator is not stable");
  }
  return d;
}

ClippedOptimal::ClippedOptimal(ClippedOptimalDesign design)
    : d_(std::move(design)),
      q_pred_(Eigen::VectorXd::Zero(2 * d_.n)),
      q_post_(Eigen::VectorXd::Zero(2 * d_.n)),
      innovation_(Eigen::VectorXd::Zero(d_.n)) {}

double ClippedOptimal::Step(std::int64_t k, const double* abs_acc_prev_mm_s2, double f_prev_kN, double f_kN) {
  if (k > 0) {
    // Update with the accelerations of sample k-1, then predict sample k (force held over the step).
    const Eigen::Map<const Eigen::VectorXd> a(abs_acc_prev_mm_s2, d_.n);
    innovation_ = a - d_.Da * f_prev_kN;
    innovation_.noalias() -= d_.Ca * q_pred_;
    q_post_ = q_pred_;
    q_post_.noalias() += d_.L * innovation_;
    q_pred_.noalias() = d_.Phi * q_post_;
    q_pred_.noalias() += d_.Gamma.col(0) * f_prev_kN;
  }
  f_c_ = -d_.K.dot(q_pred_);
  return (f_c_ - f_kN) * f_kN > 0.0 ? d_.options.max_current_A : 0.0;
}

}  // namespace rths::control
