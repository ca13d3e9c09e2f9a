#pragma once
/// @file Small linear-systems toolbox for controller design and analysis (docs/controllers.md):
/// discrete SISO state-space systems, their frequency responses, series connection, ZOH and
/// Van Loan discretisation, and diagonal balancing for badly scaled realisations (the servo
/// models' phase variables span 1 to 1e7 in size).
#include <complex>
#include <vector>

#include <Eigen/Core>

#include "models/servo_linear.h"
#include "signal/butterworth.h"

namespace rths::control {

/// Discrete SISO system  x_{k+1} = A x_k + B u_k,  y_k = C x_k + D u_k  at step dt_s [s].
/// dim A = n x n, B = n, C = n (row), n >= 0 (n = 0: a static gain D).
struct DiscreteSs {
  Eigen::MatrixXd A;
  Eigen::VectorXd B;
  Eigen::RowVectorXd C;
  double D = 0.0;
  double dt_s = 0.0;

  int order() const { return static_cast<int>(A.rows()); }
  /// H(z) = C (zI - A)^-1 B + D at z = e^{j 2 pi f dt}.
  std::complex<double> Response(double f_hz) const;
};

/// y_k of `s` driven by u_k from rest (x_0 = 0), k = 0 .. u.size()-1. Allocates (analysis only).
std::vector<double> Simulate(const DiscreteSs& s, const std::vector<double>& u);

/// A static gain D (n = 0).
DiscreteSs StaticGain(double d, double dt_s);
/// FIR filter y_k = sum_i h[i] u_{k-i}, i = 0 .. h.size()-1 (shift-register realisation).
DiscreteSs Fir(const Eigen::VectorXd& h, double dt_s);
/// A cascade of second-order sections (signal::Biquad conventions), in order.
DiscreteSs FromSos(const signal::Sos& sos, double dt_s);
/// y = H2(H1(u)): first `h1`, then `h2`. Both must share dt_s.
DiscreteSs Series(const DiscreteSs& h1, const DiscreteSs& h2);
/// w1 H1 + w2 H2 (parallel connection, same input). Both must share dt_s.
DiscreteSs Blend(const DiscreteSs& h1, double w1, const DiscreteSs& h2, double w2);
/// The three-pole servo model G(s) = K / ((s + p)(s^2 + b s + c)) (Eq. 15, N = 3) discretised
/// with a zero-order hold (models::LinearServo: phase variables, y_k = C z_k, strictly proper).
DiscreteSs ServoZoh(const models::ServoModel3& m, double dt_s);

/// Diagonal similarity d (powers of 2) such that diag(d)^-1 M diag(d) has rows and columns of
/// comparable 1-norm (Parlett & Reinsch 1969, as LAPACK's dgebal without permutation).
Eigen::VectorXd BalancingScale(const Eigen::MatrixXd& M);
/// e^{M t}, computed in the balanced basis of M (exact similarity; accurate for the servo models).
Eigen::MatrixXd BalancedExp(const Eigen::MatrixXd& M, double t);

/// Zero-order-hold discretisation of x' = A x + B u:  Phi = e^{A dt}, Gamma = int_0^dt e^{A s} ds B
/// (one exponential of the augmented matrix [[A, B], [0, 0]]).
void ZohDiscretise(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double dt_s, Eigen::MatrixXd* Phi,
                   Eigen::MatrixXd* Gamma);
/// Van Loan (1978): covariance of the discrete process noise for x' = A x + w, E[w w^T] = Qc delta:
/// Q_d = int_0^dt e^{A s} Qc e^{A^T s} ds, from exp([[-A, Qc], [0, A^T]] dt) = [[., F12], [0, F22]]
/// as Q_d = F22^T F12 (then symmetrised).
Eigen::MatrixXd VanLoanCovariance(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Qc, double dt_s);

}  // namespace rths::control
