#pragma once
/// @file The maRTHS benchmark's physical frame as the reference code feeds its force back
/// (physicalFrame_feedbackForce.m and the Simulink subsystem "Feedback Force Computation" of
/// FermandoisLab/maRTHS-bmk-RoDeAC; docs/marths.md "Feedback force").
///
/// The physical specimen is a one-bay frame, pinned at its base, 5 DOFs without axial
/// deformation: q = [X (top translation, m), theta_1 (interface node, rad), theta_2 (the other top
/// node), theta_3, theta_4 (base nodes)]. Beam L_b = 0.762 m, I_b = 4.21372e-7 m^4; columns
/// L_c = 0.64135 m, I_c = 0.7 x 2.520 in^4 (the code's column tuning factor), E = 200 GPa, steel
/// 7850 kg/m^3; lumped masses x 1.1:
///
///     M = 1.1 diag((m_b + 2 m_c)/2, J_12, J_12, J_34, J_34),
///     J_12 = (m_b/2 L_b^2 + m_c/2 L_c^2)/3,  J_34 = m_c/2 L_c^2/3;
///
/// K assembled from the Euler-Bernoulli element matrices as the script does; C = sum over the
/// modes of M (2 zeta w_i phi_i phi_i^T / m_i) M with zeta = 5 % and each w_i rounded to
/// 0.01 rad/s (as the script rounds it).
///
/// The actuators impose X and theta_1; the other rotations follow statically:
/// [theta_2, theta_3, theta_4] = -K_oo^-1 K_ot [X, theta_1]. The force on the numerical
/// substructure is the frame's dynamic restoring force
///
///     f = K q + C q' + M q'',  q' and q'' by backward differences of q at the loop's step
///
/// (Simulink's Derivative block: (q_k - q_{k-1}) / dt, 0 at the first sample; q'' the same of q';
/// docs/marths.md "Decisions"), fed back with the signs the model wires: F_27 = f_1 [N],
/// M_21 = -f_2 and M_29 = -f_3 [N m] (the frame's rotations are the numerical model's with the
/// opposite sign, its "change of local coordinate axis" gains).
#include <Eigen/Core>

namespace rths::models::marths {

/// Immutable description of the feedback frame.
struct FeedbackFrame {
  Eigen::Matrix<double, 5, 5> K, C, M;     ///< SI
  Eigen::Matrix<double, 3, 2> condense;   ///< -K_oo^-1 K_ot
  double dt_s = 0.0;
};

/// physicalFrame_feedbackForce.m at the loop's step dt_s (> 0; throws rths::Error otherwise).
FeedbackFrame MakeFeedbackFrame(double dt_s);

/// The forces on the numerical substructure's DOFs 27, 21, 29.
struct InterfaceForces {
  double F27_N = 0.0;
  double M21_N_m = 0.0;
  double M29_N_m = 0.0;
};

/// Per-step state of the backward differences.
struct FeedbackFrameState {
  Eigen::Matrix<double, 5, 1> q_prev = Eigen::Matrix<double, 5, 1>::Zero();
  Eigen::Matrix<double, 5, 1> qd_prev = Eigen::Matrix<double, 5, 1>::Zero();
  bool started = false;          ///< false before the first sample
  double theta2_rad = 0.0;       ///< the last sample's theta_2 (the reference code's rm2_hat)
};

/// The force for the imposed motion (x [m], theta [rad]) at this sample (the file comment).
/// Allocates nothing.
InterfaceForces FeedbackForce(const FeedbackFrame& f, FeedbackFrameState* state, double x_m,
                              double theta_rad);

}  // namespace rths::models::marths
