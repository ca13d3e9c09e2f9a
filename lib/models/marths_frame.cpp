#include "models/marths_frame.h"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "core/error.h"

namespace rths::models::marths {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat5 = Eigen::Matrix<double, 5, 5>;

/// Plane beam-column element stiffness in local axes (x' axial, y' transverse, rotation z'),
/// axial terms (rows and columns 1 and 4) zeroed as the script does.
Mat6 FrameElementNoAxial(double E, double A, double I, double L) {
  Mat6 k;
  const double a = A * E / L, b = 12 * E * I / (L * L * L), c = 6 * E * I / (L * L);
  const double d = 4 * E * I / L, e = 2 * E * I / L;
  k << a, 0, 0, -a, 0, 0,  //
      0, b, c, 0, -b, c,   //
      0, c, d, 0, -c, e,   //
      -a, 0, 0, a, 0, 0,   //
      0, -b, -c, 0, b, -c, //
      0, c, e, 0, -c, d;
  k.row(0).setZero();
  k.row(3).setZero();
  k.col(0).setZero();
  k.col(3).setZero();
  return k;
}

/// Element rotation by `theta` [rad] (local = T global).
Mat6 ElementRotation(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Mat6 T = Mat6::Zero();
  T(0, 0) = c, T(0, 1) = s, T(1, 0) = -s, T(1, 1) = c, T(2, 2) = 1;
  T(3, 3) = c, T(3, 4) = s, T(4, 3) = -s, T(4, 4) = c, T(5, 5) = 1;
  return T;
}

}  // namespace

FeedbackFrame MakeFeedbackFrame(double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("maRTHS feedback frame", "dt_s must be > 0");
  constexpr double kInch = 25.4 / 1000.0;
  const double Lb = 762.0 / 1000.0, Lc = 641.35 / 1000.0;
  const double Ic = 2.520 * std::pow(kInch, 4) * 0.7, Ib = 4.21372e-7 * 1.0;
  const double Ac = 1.670 * kInch * kInch, Ab = 7.56e-4;
  const double E = 200e9, rho = 7.85e3;
  const double pi = 3.14159265358979323846;
  const Mat6 Tc = ElementRotation(pi / 2.0), Tb = ElementRotation(0.0);
  const Mat6 Kc = Tc.transpose() * FrameElementNoAxial(E, Ac, Ic, Lc) * Tc;
  const Mat6 Kb = Tb.transpose() * FrameElementNoAxial(E, Ab, Ib, Lb) * Tb;
  // The script's assembly, with its 1-based element indices (K(i, j) below is Kc(i - 1, j - 1)).
  auto c = [&](int i, int j) { return Kc(i - 1, j - 1); };
  auto b = [&](int i, int j) { return Kb(i - 1, j - 1); };
  FeedbackFrame f;
  f.dt_s = dt_s;
  f.K << c(4, 4) * 2, c(4, 6), c(4, 6), c(4, 3), c(4, 3),  //
      c(6, 4), c(6, 6) + b(6, 6), b(6, 3), 0, c(6, 3),      //
      c(6, 4), b(3, 6), c(6, 6) + b(3, 3), c(6, 3), 0,      //
      c(3, 4), 0, c(3, 6), c(3, 3), 0,                      //
      c(3, 4), c(3, 6), 0, 0, c(3, 3);
  const double mass_b = rho * Ab * Lb, mass_c = rho * Ac * Lc;
  const double M1x = (mass_b + mass_c * 2) / 2 * 1.1;
  const double M12z = (mass_b / 2 * Lb * Lb + mass_c / 2 * Lc * Lc) / 3 * 1.1;
  const double M34z = mass_c / 2 * Lc * Lc / 3 * 1.1;
  f.M = Eigen::Matrix<double, 5, 1>(M1x, M12z, M12z, M34z, M34z).asDiagonal();
  // Modal damping, 5 % in every mode, frequencies rounded to 0.01 rad/s as the script rounds them.
  const Eigen::GeneralizedSelfAdjointEigenSolver<Mat5> eig(f.K, f.M);
  f.C.setZero();
  for (int i = 0; i < 5; ++i) {
    const double w = std::round(100.0 * std::sqrt(eig.eigenvalues()(i))) / 100.0;
    const Eigen::Matrix<double, 5, 1> phi = eig.eigenvectors().col(i);
    const double m = phi.dot(f.M * phi);
    f.C += f.M * (2.0 * 0.05 * w * phi * phi.transpose() / m) * f.M;
  }
  const Eigen::Matrix3d Koo = f.K.block<3, 3>(2, 2);
  const Eigen::Matrix<double, 3, 2> Kot = f.K.block<3, 2>(2, 0);
  f.condense = -Koo.inverse() * Kot;
  return f;
}

InterfaceForces FeedbackForce(const FeedbackFrame& f, FeedbackFrameState* state, double x_m,
                              double theta_rad) {
  FeedbackFrameState& s = *state;
  Eigen::Matrix<double, 5, 1> q;
  q(0) = x_m;
  q(1) = theta_rad;
  q.tail<3>() = f.condense * Eigen::Vector2d(x_m, theta_rad);
  Eigen::Matrix<double, 5, 1> qd = Eigen::Matrix<double, 5, 1>::Zero();
  Eigen::Matrix<double, 5, 1> qdd = Eigen::Matrix<double, 5, 1>::Zero();
  if (s.started) {
    qd = (q - s.q_prev) / f.dt_s;
    qdd = (qd - s.qd_prev) / f.dt_s;
  }
  const Eigen::Matrix<double, 5, 1> force = f.K * q + f.C * qd + f.M * qdd;
  s.q_prev = q;
  s.qd_prev = qd;
  s.started = true;
  s.theta2_rad = q(2);
  return {force(0), -force(1), -force(2)};
}

}  // namespace rths::models::marths
