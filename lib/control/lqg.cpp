#include "control/lqg.h"

#include <cmath>
#include <numbers>
#include <tuple>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "control/dare.h"
#include "control/lti.h"
#include "core/error.h"

namespace rths::control {

LqgDesign MakeLqgDesign(const models::ServoModel3& m, const control::LqgConfig& w, double dt_s) {
  RequireServoModel(m, "controller.model");
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  for (auto [key, v, zero_ok] : {std::tuple{"controller.lqg.q", w.q, false}, {"controller.lqg.w_f_hz", w.w_f_hz, false},
                                 {"controller.lqg.xi_f", w.xi_f, false}, {"controller.lqg.eta_f", w.eta_f, true},
                                 {"controller.lqg.W", w.W, false}, {"controller.lqg.V", w.V, false}}) {
    if (!std::isfinite(v) || v < 0.0 || (v == 0.0 && !zero_ok)) {
      throw Error(key, fmt::format("{}: allowed {} (finite)", v, zero_ok ? ">= 0" : "> 0"));
    }
  }
  LqgDesign d;
  d.model = m;
  d.weights = w;
  d.dt_s = dt_s;
  const double d2 = m.p + m.b, d1 = m.p * m.b + m.c, d0 = m.p * m.c;
  const double wf = 2.0 * std::numbers::pi * w.w_f_hz;
  // Eqs. 23-27 augmented: x = [e, e', e'', z_f1, z_f2].
  d.A.setZero();
  d.A(0, 1) = 1.0;
  d.A(1, 2) = 1.0;
  d.A.row(2).head<3>() << -d0, -d1, -d2;
  d.A(2, 3) = m.K * wf * wf;                     // E C_f, E = B
  d.A(2, 4) = m.K * 2.0 * w.xi_f * wf * w.eta_f;
  d.A(3, 4) = 1.0;                               // A_f
  d.A(4, 3) = -wf * wf;
  d.A(4, 4) = -2.0 * w.xi_f * wf;
  d.B << 0, 0, m.K, 0, 0;
  d.G << 0, 0, 0, 0, 1;
  d.C << 1, 0, 0, 0, 0;

  Eigen::MatrixXd phi, gamma;
  ZohDiscretise(d.A, d.B, dt_s, &phi, &gamma);
  d.Phi = phi;
  d.Gamma = gamma;
  d.Qd = VanLoanCovariance(d.A, d.G * w.W * d.G.transpose(), dt_s);

  const Eigen::MatrixXd one = Eigen::MatrixXd::Constant(1, 1, 1.0);
  const DareSolution lqr = SolveDare(phi, gamma, w.q * d.C.transpose() * d.C, one, "controller.lqg: LQR");
  d.P = lqr.X;
  d.Kc = lqr.K;
  d.regulator_poles = lqr.closed_loop;
  d.lqr_residual = lqr.residual;
  d.lqr_iterations = lqr.iterations;

  const DareSolution kf = SolveDare(phi.transpose(), d.C.transpose(), d.Qd, Eigen::MatrixXd::Constant(1, 1, w.V),
                                    "controller.lqg: Kalman filter");
  d.S = kf.X;
  d.L = d.S * d.C.transpose() / ((d.C * d.S * d.C.transpose()).value() + w.V);
  d.estimator_poles = kf.closed_loop;
  d.kalman_residual = kf.residual;
  d.kalman_iterations = kf.iterations;
  return d;
}

DiscreteSs LqgDesign::Feedback() const {
  const Matrix5d i_lc = Matrix5d::Identity() - L * C;
  const Matrix5d reg = Phi - Gamma * Kc;
  return {reg * i_lc, reg * L, -Kc * i_lc, -(Kc * L).value(), dt_s};
}

FeedforwardLqg::FeedforwardLqg(const models::ServoModel3& model, const control::LqgConfig& weights,
                               bool half_step_ahead, double dt_s)
    : a_(FeedforwardFor(model, "controller.model")),
      half_step_ahead_(half_step_ahead),
      design_(MakeLqgDesign(model, weights, dt_s)) {}

Command FeedforwardLqg::Step(const Derivatives& d, const Measurement& m) {
  const double u_ff = FeedforwardCommand(a_, d, half_step_ahead_, design_.dt_s);  // Eq. 19
  const double e = m.y_mm - d.r;                                                  // y~_k (Eq. 13)
  const Vector5d x = x_pred_ + design_.L * (e - design_.C * x_pred_);             // measurement update
  const double u_fb = -(design_.Kc * x).value();                                  // LQR
  x_pred_ = design_.Phi * x + design_.Gamma * u_fb;                               // time update
  return {u_ff + u_fb, u_ff, u_fb};                                               // Eq. 14
}

ControllerLti FeedforwardLqg::Linearize(double) const {
  return {FeedforwardFir(a_, half_step_ahead_, design_.dt_s), true, design_.Feedback()};
}

}  // namespace rths::control
