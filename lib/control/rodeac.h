#pragma once
/// @file RoDeAC, the robust decentralised adaptive compensator of Quiroz, Galmez & Fermandois
/// (2024) for the maRTHS benchmark: one per actuator, as its reference code runs it
/// (S3_Controller.m and the Simulink subsystems "RLS-AC1/2" of FermandoisLab/maRTHS-bmk-RoDeAC;
/// docs/marths.md "RoDeAC").
///
/// The command is an FIR filter of the target x_t with n = 4 taps, newest first:
///
///     u_k = theta_k^T T_k,   T_k = [x_t,k, x_t,k-1, x_t,k-2, x_t,k-3]
///
/// and theta is identified on line by recursive least squares as the inverse plant: the filtered
/// command u_f against the filtered measured strokes, both through the same 4th-order Butterworth
/// low-pass at 20 Hz (MATLAB's butter(4, 20/(fs/2)), here signal::ButterworthLowpass, the same
/// bilinear design):
///
///     phi_k = [y_f,k, y_f,k-1, y_f,k-2, y_f,k-3],   e_k = u_f,k - phi_k^T theta_{k-1}
///     K_k = P_{k-1} phi_k / (lambda + phi_k^T P_{k-1} phi_k)
///     theta_k = theta_{k-1} + K_k e_k,   P_k = (P_{k-1} - K_k phi_k^T P_{k-1}) / lambda
///
/// from theta_{-1} = theta_0 and P_{-1} = P_0 (the offline calibration's Initial_parameters.mat,
/// data/marths/rodeac_initial_parameters.txt), forgetting factor lambda = 1. u_f,k is the filter's
/// output for u_k, so u_k, theta_k and u_f,k form an algebraic loop through the filter's direct
/// term b: u_f,k = b u_k + s_k (s_k from the filter's state). Simulink solves it iteratively; it is
/// linear in u_k, so here it is solved exactly:
///
///     u_k (1 - b T_k^T K_k) = T_k^T theta_{k-1} + T_k^T K_k (s_k - phi_k^T theta_{k-1}).
#include <array>

#include <Eigen/Core>

#include "signal/butterworth.h"

namespace rths::control {

/// One actuator's RoDeAC design (immutable).
struct RodeacDesign {
  Eigen::Vector4d theta0 = Eigen::Vector4d::Zero();   ///< initial taps [-], newest first
  Eigen::Matrix4d P0 = Eigen::Matrix4d::Zero();       ///< initial inverse correlation [1/mm^2]
  double forgetting = 1.0;                            ///< lambda, in (0, 1]
  signal::Sos filter;                                 ///< the noise filter (both paths)
};

/// The reference code's design for sample rate fs [Hz]: its initial parameters, lambda = 1 and
/// the 4th-order Butterworth at 20 Hz. Throws rths::Error if fs is not above 40 Hz.
RodeacDesign MakeRodeacDesign(const Eigen::Vector4d& theta0, const Eigen::Matrix4d& P0,
                              double fs_hz, double forgetting = 1.0, int filter_order = 4,
                              double filter_hz = 20.0);

/// Per-step state.
struct RodeacState {
  Eigen::Vector4d theta = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  Eigen::Vector4d target_taps = Eigen::Vector4d::Zero();    ///< T_k [mm]
  Eigen::Vector4d measured_taps = Eigen::Vector4d::Zero();  ///< phi_k [mm]
  signal::SosFilter measured_filter, command_filter;
};

/// At rest with theta_0 and P_0. Allocates once.
RodeacState RodeacAtRest(const RodeacDesign& d);

/// u_k [mm] from the target x_t,k and the measured stroke y_k [mm] (the file comment).
/// Allocates nothing.
double RodeacStep(const RodeacDesign& d, RodeacState* s, double target_mm, double measured_mm);

}  // namespace rths::control
