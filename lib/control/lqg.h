#pragma once
/// @file The proposed controller G_FF + LQG (Eqs. 14, 19, 23-27; docs/models.md sections 2 and 4):
/// the model-inverse feedforward of `model` plus LQG feedback on the deviation system.
///
/// Deviation system (Eqs. 12-13, 23-24) in phase variables of G(s) = K / (s^3 + d2 s^2 + d1 s + d0):
///   z = [e, e', e''],  A = [[0, 1, 0], [0, 0, 1], [-d0, -d1, -d2]],  B = E = [0, 0, K]^T,  C = [1, 0, 0],
/// disturbance w_f = C_f z_f from white noise w through the shaping filter (Eqs. 25-27)
///   A_f = [[0, 1], [-w_f^2, -2 xi_f w_f]],  E_f = [0, 1]^T,  C_f = [w_f^2, 2 xi_f w_f eta_f],
/// augmented to x = [z; z_f] (5 states):
///   A_a = [[A, E C_f], [0, A_f]],  B_a = [B; 0],  G_a = [0; E_f],  C_a = [C, 0].
/// Discretised at dt: (Phi, Gamma) by zero-order hold, Q_d = int_0^dt e^{A_a s} G_a W G_a^T e^{A_a^T s} ds
/// by Van Loan's method. Gains:
///   LQR on sum(q e_k^2 + u_k^2):   P = DARE(Phi, Gamma, q C_a^T C_a, 1),
///                                  K_c = (1 + Gamma^T P Gamma)^-1 Gamma^T P Phi;
///   Kalman (current estimator):    S = DARE(Phi^T, C_a^T, Q_d, V),  L = S C_a^T (C_a S C_a^T + V)^-1.
/// Step k (e_k = y_k - r_k, the deviation output y~ of Eq. 13, minus the tracking error of Eq. 6):
///   x+_k = x-_k + L (e_k - C_a x-_k);  u_FB,k = -K_c x+_k;  x-_{k+1} = Phi x+_k + Gamma u_FB,k;
///   u_k = u_FF,k + u_FB,k   (Eq. 14), x-_0 = 0.
/// With the default weights (q = 10, w_f = 2 pi 3, xi_f = 0.7, eta_f = 0.5, W = V = 1) and Eq. 30:
/// K_c = [2.10864, 7.86211e-3, 1.53391e-5, 2.48463e2, 9.43955],
/// L = [1.46074e-1, 2.30356e1, -1.07472e3, 1.54374e-4, 1.63384e-2] (docs/models.md section 4).
#include <Eigen/Core>

#include "control/tracking_controller.h"

namespace rths::control {

using Matrix5d = Eigen::Matrix<double, 5, 5>;
using Vector5d = Eigen::Matrix<double, 5, 1>;
using RowVector5d = Eigen::Matrix<double, 1, 5>;

struct LqgDesign {
  models::ServoModel3 model;  ///< design model (Eq. 30 in the paper)
  control::LqgConfig weights;  ///< q, shaping filter, W, V
  double dt_s = 0.0;
  Matrix5d A;                   ///< A_a, continuous
  Vector5d B;                   ///< B_a
  Vector5d G;                   ///< G_a (process noise input)
  RowVector5d C;                ///< C_a
  Matrix5d Phi;                 ///< e^{A_a dt}
  Vector5d Gamma;               ///< ZOH input vector
  Matrix5d Qd;                  ///< discrete process-noise covariance (Van Loan)
  Matrix5d P;                   ///< LQR Riccati solution
  Matrix5d S;                   ///< Kalman (a priori) covariance
  RowVector5d Kc;               ///< LQR gain
  Vector5d L;                   ///< current-estimator gain
  Eigen::VectorXcd regulator_poles;  ///< eig(Phi - Gamma K_c), dim 5
  Eigen::VectorXcd estimator_poles;  ///< eig(Phi - Phi L C_a), dim 5
  double lqr_residual = 0.0, kalman_residual = 0.0;  ///< relative Riccati residuals
  int lqr_iterations = 0, kalman_iterations = 0;

  /// C_fb(z): e -> u_FB of the recursion above (x = x-):
  ///   A_k = (Phi - Gamma K_c)(I - L C_a), B_k = (Phi - Gamma K_c) L, C_k = -K_c (I - L C_a), D_k = -K_c L.
  DiscreteSs Feedback() const;
};

/// Designs the LQG. Throws rths::Error naming "controller.model" for a bad model and
/// "controller.lqg" (with LQR or Kalman) when a Riccati equation has no stabilising solution.
LqgDesign MakeLqgDesign(const models::ServoModel3& model, const control::LqgConfig& weights, double dt_s);

/// `ff_lqg`: u_k = u_FF,k (Eq. 19 of `model`, or half a step ahead) + u_FB,k (the recursion above).
class FeedforwardLqg final : public TrackingController {
 public:
  FeedforwardLqg(const models::ServoModel3& model, const control::LqgConfig& weights, bool half_step_ahead,
                 double dt_s);
  Command Step(const Derivatives& d, const Measurement& m) override;
  ControllerLti Linearize(double current_A) const override;
  const LqgDesign& design() const { return design_; }
  const FeedforwardCoefficients& feedforward() const { return a_; }

 private:
  const FeedforwardCoefficients a_;
  const bool half_step_ahead_;
  const LqgDesign design_;
  Vector5d x_pred_ = Vector5d::Zero();  ///< x-_k, the estimate before measurement k
};

}  // namespace rths::control
