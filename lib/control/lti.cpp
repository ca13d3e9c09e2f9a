#include "control/lti.h"

#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "models/servo_linear.h"

namespace rths::control {

using cd = std::complex<double>;

std::complex<double> DiscreteSs::Response(double f_hz) const {
  if (order() == 0) return D;
  const cd z = std::polar(1.0, 2.0 * std::numbers::pi * f_hz * dt_s);
  const Eigen::MatrixXcd zi_a = z * Eigen::MatrixXcd::Identity(order(), order()) - A.cast<cd>();
  const Eigen::VectorXcd x = zi_a.partialPivLu().solve(B.cast<cd>());
  return (C.cast<cd>() * x).value() + D;
}

std::vector<double> Simulate(const DiscreteSs& s, const std::vector<double>& u) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.order());
  std::vector<double> y(u.size());
  for (std::size_t k = 0; k < u.size(); ++k) {
    y[k] = (s.C * x).value() + s.D * u[k];
    x = s.A * x + s.B * u[k];
  }
  return y;
}

DiscreteSs StaticGain(double d, double dt_s) {
  return {Eigen::MatrixXd(0, 0), Eigen::VectorXd(0), Eigen::RowVectorXd(0), d, dt_s};
}

DiscreteSs Fir(const Eigen::VectorXd& h, double dt_s) {
  const Eigen::Index n = h.size() - 1;  // x_k = [u_{k-1}, ..., u_{k-n}]
  DiscreteSs s{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n), h.tail(n).transpose(), h(0), dt_s};
  if (n > 0) s.B(0) = 1.0;
  for (Eigen::Index i = 1; i < n; ++i) s.A(i, i - 1) = 1.0;
  return s;
}

DiscreteSs FromSos(const signal::Sos& sos, double dt_s) {
  DiscreteSs out = StaticGain(1.0, dt_s);
  for (const signal::Biquad& q : sos.sections) {
    // Direct form II transposed: y = b0 x + z1; z1 <- b1 x - a1 y + z2; z2 <- b2 x - a2 y.
    DiscreteSs s{Eigen::MatrixXd(2, 2), Eigen::VectorXd(2), Eigen::RowVectorXd(2), q.b0, dt_s};
    s.A << -q.a1, 1.0, -q.a2, 0.0;
    s.B << q.b1 - q.a1 * q.b0, q.b2 - q.a2 * q.b0;
    s.C << 1.0, 0.0;
    out = Series(out, s);
  }
  return out;
}

DiscreteSs Series(const DiscreteSs& h1, const DiscreteSs& h2) {
  const int n1 = h1.order(), n2 = h2.order();
  DiscreteSs s{Eigen::MatrixXd::Zero(n1 + n2, n1 + n2), Eigen::VectorXd(n1 + n2),
               Eigen::RowVectorXd(n1 + n2), h2.D * h1.D, h1.dt_s};
  s.A.topLeftCorner(n1, n1) = h1.A;
  s.A.bottomLeftCorner(n2, n1) = h2.B * h1.C;
  s.A.bottomRightCorner(n2, n2) = h2.A;
  s.B << h1.B, h2.B * h1.D;
  s.C << h2.D * h1.C, h2.C;
  return s;
}

DiscreteSs Blend(const DiscreteSs& h1, double w1, const DiscreteSs& h2, double w2) {
  const int n1 = h1.order(), n2 = h2.order();
  DiscreteSs s{Eigen::MatrixXd::Zero(n1 + n2, n1 + n2), Eigen::VectorXd(n1 + n2),
               Eigen::RowVectorXd(n1 + n2), w1 * h1.D + w2 * h2.D, h1.dt_s};
  s.A.topLeftCorner(n1, n1) = h1.A;
  s.A.bottomRightCorner(n2, n2) = h2.A;
  s.B << h1.B, h2.B;
  s.C << w1 * h1.C, w2 * h2.C;
  return s;
}

DiscreteSs ServoZoh(const models::ServoModel3& m, double dt_s) {
  const models::LinearServo g = models::LinearServo::Make(m, dt_s);
  return {g.Phi, g.Gamma, g.C, 0.0, dt_s};
}

Eigen::VectorXd BalancingScale(const Eigen::MatrixXd& M) {
  const Eigen::Index n = M.rows();
  Eigen::MatrixXd a = M;
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (bool done = false; !done;) {
    done = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      double c = a.col(i).cwiseAbs().sum() - std::abs(a(i, i));
      double r = a.row(i).cwiseAbs().sum() - std::abs(a(i, i));
      if (c == 0.0 || r == 0.0) continue;
      const double s = c + r;
      double f = 1.0;
      while (c < r / 2.0) f *= 2.0, c *= 4.0;
      while (c > r * 2.0) f /= 2.0, c /= 4.0;
      if ((c + r) / f < 0.95 * s) {  // scale column i by f and row i by 1/f
        done = false;
        d(i) *= f;
        a.col(i) *= f;
        a.row(i) /= f;
      }
    }
  }
  return d;
}

Eigen::MatrixXd BalancedExp(const Eigen::MatrixXd& M, double t) {
  const Eigen::VectorXd d = BalancingScale(M);
  const Eigen::MatrixXd balanced = d.cwiseInverse().asDiagonal() * M * d.asDiagonal();
  const Eigen::MatrixXd e = (balanced * t).exp();
  return d.asDiagonal() * e * d.cwiseInverse().asDiagonal();
}

void ZohDiscretise(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double dt_s, Eigen::MatrixXd* Phi,
                   Eigen::MatrixXd* Gamma) {
  const Eigen::Index n = A.rows(), m = B.cols();
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + m, n + m);
  aug.topLeftCorner(n, n) = A;
  aug.topRightCorner(n, m) = B;
  const Eigen::MatrixXd e = BalancedExp(aug, dt_s);
  *Phi = e.topLeftCorner(n, n);
  *Gamma = e.topRightCorner(n, m);
}

Eigen::MatrixXd VanLoanCovariance(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Qc, double dt_s) {
  const Eigen::Index n = A.rows();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  m.topLeftCorner(n, n) = -A;
  m.topRightCorner(n, n) = Qc;
  m.bottomRightCorner(n, n) = A.transpose();
  const Eigen::MatrixXd e = BalancedExp(m, dt_s);
  const Eigen::MatrixXd q = e.bottomRightCorner(n, n).transpose() * e.topRightCorner(n, n);
  return 0.5 * (q + q.transpose());
}

}  // namespace rths::control
