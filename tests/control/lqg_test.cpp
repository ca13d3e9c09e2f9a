// Tests for lib/control/dare, lti (ZOH, Van Loan), lqg and analysis: the DARE against closed forms
// and under bad scaling, the LQG gains and loop margins of docs/models.md section 4, and the closed loop.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Dense>

#include "control/analysis.h"
#include "control/dare.h"
#include "control/lqg.h"
#include "control/lti.h"
#include "core/error.h"
#include "scenario/scenario.h"

namespace ctl = rths::control;
using rths::models::ServoPreset;

namespace {

constexpr double kDt = 0.0005;

Eigen::MatrixXd M1(double v) { return Eigen::MatrixXd::Constant(1, 1, v); }

// Scalar DARE x = a^2 x - a^2 b^2 x^2 / (r + b^2 x) + q, i.e. b^2 x^2 + (r (1 - a^2) - q b^2) x - q r = 0;
// the stabilising root is the positive one.
double ScalarDare(double a, double b, double q, double r) {
  const double B = r * (1.0 - a * a) - q * b * b;
  return (-B + std::sqrt(B * B + 4.0 * b * b * q * r)) / (2.0 * b * b);
}

}  // namespace

TEST_CASE("DARE: scalar closed forms (stable and unstable a)") {
  struct Case { double a, b, q, r; };
  for (const Case& c : {Case{2.0, 1.0, 1.0, 1.0}, Case{0.5, 2.0, 3.0, 0.7}, Case{0.999, 1e-3, 1e4, 1.0},
                        Case{-1.5, 0.2, 0.01, 5.0}}) {
    const ctl::DareSolution s = ctl::SolveDare(M1(c.a), M1(c.b), M1(c.q), M1(c.r));
    const double x = ScalarDare(c.a, c.b, c.q, c.r);
    CHECK(s.X(0, 0) == doctest::Approx(x).epsilon(1e-12));
    CHECK(s.K(0, 0) == doctest::Approx(c.a * c.b * x / (c.r + c.b * c.b * x)).epsilon(1e-12));
    CHECK(std::abs(s.closed_loop(0)) < 1.0);
  }
  CHECK(ctl::SolveDare(M1(2.0), M1(1.0), M1(1.0), M1(1.0)).X(0, 0) == doctest::Approx(2.0 + std::sqrt(5.0)));
}

TEST_CASE("DARE: a badly scaled realisation gives the transformed solution (states 1 .. 1e7)") {
  // A well-scaled 3-state problem, and the same in the basis x = T x', T = diag(1, 1e-4, 1e-7):
  // X' = T X T, K' = K T.
  Eigen::Matrix3d A;
  A << 0.9, 0.1, 0.0, -0.2, 0.95, 0.05, 0.01, -0.3, 0.7;
  const Eigen::Vector3d B(0.0, 0.1, 1.0);
  const Eigen::Matrix3d Q = Eigen::Vector3d(1.0, 0.0, 0.0) * Eigen::RowVector3d(1.0, 0.0, 0.0) * 10.0;
  const Eigen::Vector3d t(1.0, 1e-4, 1e-7);
  const Eigen::Matrix3d T = t.asDiagonal(), Ti = t.cwiseInverse().asDiagonal();
  const ctl::DareSolution s = ctl::SolveDare(A, B, Q, M1(1.0));
  const ctl::DareSolution w = ctl::SolveDare(Ti * A * T, Ti * B, T * Q * T, M1(1.0));
  CHECK(((T * s.X * T - w.X).array().abs() <= 1e-9 * w.X.cwiseAbs().array() + 1e-300).all());
  CHECK(((s.K * T - w.K).array().abs() <= 1e-9 * w.K.cwiseAbs().array()).all());
  CHECK(s.residual < 1e-12);
  CHECK(w.residual < 1e-12);
}

TEST_CASE("DARE: no stabilising solution is an error that says so") {
  // An unstable mode the input cannot reach.
  Eigen::Matrix2d A;
  A << 2.0, 0.0, 0.0, 0.5;
  bool thrown = false;
  try {
    ctl::SolveDare(A, Eigen::Vector2d(0.0, 1.0), Eigen::Matrix2d::Identity(), M1(1.0), "controller.lqg: LQR");
  } catch (const rths::Error& e) {
    thrown = true;
    CHECK(e.where() == "controller.lqg: LQR");
    CHECK(std::string(e.what()).find("stabilising") != std::string::npos);
  }
  CHECK(thrown);
  // An unstable mode the weights cannot see (SDA needs (Q, A) detectable).
  CHECK_THROWS_AS(ctl::SolveDare(M1(2.0), M1(1.0), M1(0.0), M1(1.0)), rths::Error);
  CHECK_THROWS_AS(ctl::SolveDare(M1(0.5), M1(1.0), M1(1.0), M1(0.0)), rths::Error);  // R not > 0
}

TEST_CASE("ZOH and Van Loan: first-order closed forms") {
  const double a = 150.0, b = 3.0, q = 2.0;
  Eigen::MatrixXd phi, gamma;
  ctl::ZohDiscretise(M1(-a), M1(b), kDt, &phi, &gamma);
  CHECK(phi(0, 0) == doctest::Approx(std::exp(-a * kDt)).epsilon(1e-14));
  CHECK(gamma(0, 0) == doctest::Approx(b * (1.0 - std::exp(-a * kDt)) / a).epsilon(1e-13));
  const Eigen::MatrixXd qd = ctl::VanLoanCovariance(M1(-a), M1(q), kDt);
  CHECK(qd(0, 0) == doctest::Approx(q * (1.0 - std::exp(-2.0 * a * kDt)) / (2.0 * a)).epsilon(1e-12));
  // A double integrator with white acceleration: Q_d = q [[dt^3/3, dt^2/2], [dt^2/2, dt]].
  Eigen::Matrix2d A2;
  A2 << 0, 1, 0, 0;
  Eigen::Matrix2d qc = Eigen::Matrix2d::Zero();
  qc(1, 1) = q;
  const Eigen::MatrixXd q2 = ctl::VanLoanCovariance(A2, qc, kDt);
  CHECK(q2(0, 0) == doctest::Approx(q * std::pow(kDt, 3) / 3.0).epsilon(1e-12));
  CHECK(q2(0, 1) == doctest::Approx(q * kDt * kDt / 2.0).epsilon(1e-12));
  CHECK(q2(1, 1) == doctest::Approx(q * kDt).epsilon(1e-12));
}

TEST_CASE("LQG on Eq. 30 with the proposed weights: the gains of docs/models.md section 4") {
  const ctl::LqgDesign d = ctl::MakeLqgDesign(ServoPreset("avg"), {}, kDt);
  const double kc[5] = {2.10864, 7.86211e-3, 1.53391e-5, 2.48463e2, 9.43955};
  const double l[5] = {1.46074e-1, 2.30356e1, -1.07472e3, 1.54374e-4, 1.63384e-2};
  for (int i = 0; i < 5; ++i) {
    CAPTURE(i);
    CHECK(d.Kc(i) == doctest::Approx(kc[i]).epsilon(1e-5));  // the spec gives 6 digits
    CHECK(d.L(i) == doctest::Approx(l[i]).epsilon(1e-5));
  }
  CHECK(d.lqr_residual < 1e-12);
  CHECK(d.kalman_residual < 1e-12);
  CHECK(d.regulator_poles.cwiseAbs().maxCoeff() < 1.0);
  CHECK(d.estimator_poles.cwiseAbs().maxCoeff() < 1.0);
  // The Riccati solutions are symmetric positive definite on the states that matter.
  CHECK((d.P - d.P.transpose()).norm() <= 1e-12 * d.P.norm());
  CHECK(d.S.selfadjointView<Eigen::Lower>().eigenvalues().minCoeff() > 0.0);
  // Phi and Gamma are the ZOH of the augmented model; the servo block equals models::LinearServo's.
  const ctl::DiscreteSs g = ctl::ServoZoh(ServoPreset("avg"), kDt);
  CHECK((d.Phi.topLeftCorner<3, 3>() - g.A).norm() <= 1e-12 * g.A.norm());
  CHECK((d.Gamma.head<3>() - g.B).norm() <= 1e-12 * g.B.norm());
  CHECK(d.Gamma.tail<2>().norm() == 0.0);  // the shaping filter is not driven by u
}

TEST_CASE("LQG loop margins: 26.2 Hz, 63.3 deg, 5.56 dB on avg; delay margins 5.6 / 6.7 / 7.3 ms") {
  const ctl::LqgDesign d = ctl::MakeLqgDesign(ServoPreset("avg"), {}, kDt);
  struct Case { const char* m; double dm_ms; };
  for (const Case& c : {Case{"0.0A", 5.6}, Case{"avg", 6.7}, Case{"2.5A", 7.3}}) {
    const ctl::LoopAnalysis a = ctl::AnalyzeLoop(d.Feedback(), ctl::ServoZoh(ServoPreset(c.m), kDt));
    std::printf("LQG (avg design) on %-4s: crossover %.2f Hz, PM %.2f deg, delay margin %.3f ms, peak |S| %.3f dB "
                "at %.1f Hz, closed-loop spectral radius %.6f\n",
                c.m, a.critical.f_hz, a.critical.phase_margin_deg, a.critical.delay_margin_s * 1e3,
                a.peak_sensitivity_db, a.peak_sensitivity_hz, a.spectral_radius);
    CHECK(a.stable);
    CHECK(a.crossovers.size() == 1);
    CHECK(a.critical.delay_margin_s * 1e3 == doctest::Approx(c.dm_ms).epsilon(0.05 / c.dm_ms));
    if (std::string(c.m) == "avg") {
      CHECK(a.critical.f_hz == doctest::Approx(26.2).epsilon(0.05 / 26.2));
      CHECK(a.critical.phase_margin_deg == doctest::Approx(63.3).epsilon(0.05 / 63.3));
      CHECK(a.peak_sensitivity_db == doctest::Approx(5.56).epsilon(0.005 / 5.56));
    }
  }
}

TEST_CASE("LQG closed loop on the design model: its poles are regulator and estimator poles") {
  // The plant (3 states) with the controller (5) is the augmented design loop restricted to the
  // invariant subspace "shaping-filter states zero", so its 8 poles are among the 10 of the
  // separation principle: eig(Phi - Gamma K_c) and eig(Phi - Phi L C_a).
  const ctl::LqgDesign d = ctl::MakeLqgDesign(ServoPreset("avg"), {}, kDt);
  const ctl::LoopAnalysis a = ctl::AnalyzeLoop(d.Feedback(), ctl::ServoZoh(ServoPreset("avg"), kDt));
  REQUIRE(a.closed_loop_poles.size() == 8);
  Eigen::VectorXcd sep(10);
  sep << d.regulator_poles, d.estimator_poles;
  for (Eigen::Index i = 0; i < a.closed_loop_poles.size(); ++i) {
    CHECK((sep.array() - a.closed_loop_poles(i)).abs().minCoeff() < 1e-6);
  }
  CHECK(a.spectral_radius < 1.0);
}

TEST_CASE("LQG regulates a plant disturbed from rest (deviation system, Eqs. 23-24)") {
  // r = 0 and a plant state pushed away: the feedback alone brings y back to 0.
  ctl::FeedforwardLqg c(ServoPreset("avg"), {}, false, kDt);
  const ctl::DiscreteSs g = ctl::ServoZoh(ServoPreset("2.5A"), kDt);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(3);
  z(0) = 1.0;  // y_0 = 1 mm
  double y_late = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double y = (g.C * z).value();
    const ctl::Command u = c.Step({}, {y, 0.0, 0.0});
    CHECK(u.u_ff_mm == 0.0);
    z = g.A * z + g.B * u.u_mm;
    if (k >= 3000) y_late = std::max(y_late, std::abs(y));
  }
  CHECK(y_late < 1e-3);
}

TEST_CASE("LQG design errors name the key") {
  rths::control::LqgConfig w;
  w.W = 0.0;
  try {
    ctl::MakeLqgDesign(ServoPreset("avg"), w, kDt);
    FAIL("no error");
  } catch (const rths::Error& e) {
    CHECK(e.where() == "controller.lqg.W");
  }
}
