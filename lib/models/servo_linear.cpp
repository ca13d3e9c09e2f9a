#include "models/servo_linear.h"

#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/error.h"
#include "models/phase_lag.h"

namespace rths::models {

LinearServo LinearServo::Make(const models::ServoModel3& m, double dt_s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(m.K) || !positive(m.p) || !positive(m.b) || !positive(m.c))
    throw Error("LinearServo", fmt::format("K, p, b, c must be finite and > 0 (got K = {}, p = {}, "
                                           "b = {}, c = {})",
                                           m.K, m.p, m.b, m.c));
  if (!positive(dt_s))
    throw Error("LinearServo", fmt::format("dt_s must be finite and > 0 (got {})", dt_s));

  LinearServo s;
  s.K = m.K, s.p = m.p, s.b = m.b, s.c = m.c, s.dt_s = dt_s;
  const double d2 = m.p + m.b, d1 = m.p * m.b + m.c, d0 = m.p * m.c;
  // clang-format off
  s.A << 0, 1, 0,
         0, 0, 1,
         -d0, -d1, -d2;
  // clang-format on
  s.B << 0, 0, m.K;
  s.C << 1, 0, 0;

  // Augmented exponential exp([[A, B], [0, 0]] dt) = [[Phi, Gamma], [0, 1]] (Van Loan), taken in
  // the balanced basis z~ = D z, D = diag(1, 1/w, 1/w^2), w = d0^(1/3), where every entry of
  // A~ = D A D^-1 has the size of a pole; then Phi = D^-1 Phi~ D and Gamma = D^-1 Gamma~.
  const double w = std::cbrt(d0);
  const Eigen::Vector3d d(1.0, 1.0 / w, 1.0 / (w * w));
  Eigen::Matrix4d aug = Eigen::Matrix4d::Zero();
  aug.topLeftCorner<3, 3>() = d.asDiagonal() * s.A * d.cwiseInverse().asDiagonal();
  aug.topRightCorner<3, 1>() = d.asDiagonal() * s.B;
  const Eigen::Matrix4d e = (aug * dt_s).exp();
  s.Phi = d.cwiseInverse().asDiagonal() * e.topLeftCorner<3, 3>() * d.asDiagonal();
  s.Gamma = d.cwiseInverse().asDiagonal() * e.topRightCorner<3, 1>();
  return s;
}

double LinearServo::DcGain() const { return K / (p * c); }

double Output(const LinearServo& m, const LinearServoState& s) { return (m.C * s.z).value(); }

double OutputVelocity(const LinearServo& m, const LinearServoState& s) {
  return (m.C * (m.A * s.z)).value();
}

void Step(const LinearServo& m, LinearServoState* s, double u_mm) {
  s->z = m.Phi * s->z + m.Gamma * u_mm;
}

std::complex<double> FrequencyResponse(const LinearServo& m, double f_hz, bool discrete) {
  using cd = std::complex<double>;
  const double w = 2.0 * std::numbers::pi * f_hz;
  if (!discrete) {
    const cd s(0.0, w);
    return m.K / ((s + m.p) * (s * s + m.b * s + m.c));
  }
  const cd z = std::exp(cd(0.0, w * m.dt_s));
  const Eigen::Matrix3cd zi_phi = z * Eigen::Matrix3cd::Identity() - m.Phi.cast<cd>();
  const Eigen::Vector3cd x = zi_phi.partialPivLu().solve(m.Gamma.cast<cd>());
  return (m.C.cast<cd>() * x).value();
}

double TimeLagS(const LinearServo& m, double f_hz, bool discrete) {
  if (!(f_hz > 0.0)) throw Error("TimeLagS", fmt::format("f_hz must be > 0 (got {})", f_hz));
  return UnwrappedLagS(f_hz, m.DcGain(), [&](double f) { return FrequencyResponse(m, f, discrete); });
}

ServoModel3 ServoPreset(std::string_view name) {
  if (name == "0.0A") return {1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};  // Eq. 28
  if (name == "2.5A") return {1.613e7, 134.2, 324.6, 1.211e5, "2.5A"};  // Eq. 29
  if (name == "avg") return {1.600e7, 151.7, 250.4, 1.061e5, "avg"};    // Eq. 30
  throw Error("ServoPreset", fmt::format("unknown servo model preset \"{}\" (allowed: \"0.0A\", \"2.5A\", \"avg\")",
                                         name));
}

}  // namespace rths::models
