// RoDeAC (lib/control/rodeac.h): the algebraic loop solved exactly, and the RLS converging to the
// inverse of a plant it is run against.
#include <cmath>

#include <doctest/doctest.h>

#include "control/rodeac.h"
#include "signal/butterworth.h"

namespace {

rths::control::RodeacDesign Design(const Eigen::Vector4d& theta0, double p0) {
  return rths::control::MakeRodeacDesign(theta0, p0 * Eigen::Matrix4d::Identity(), 1024.0);
}

double Target(int k) { return 2.0 * std::sin(2 * 3.14159265358979 * 1.3 * k / 1024.0) + 0.7 * std::sin(0.05 * k); }

}  // namespace

TEST_CASE("the command satisfies the loop u = theta_k^T T_k with theta_k updated by the filtered command it produces") {
  const auto d = Design(Eigen::Vector4d(1.1, 0.2, -0.1, -0.15), 50.0);
  rths::control::RodeacState s = rths::control::RodeacAtRest(d);
  // Replay the same steps by the textbook RLS with a filter of its own, and check u against it.
  rths::signal::SosFilter fy = rths::signal::SosAtRest(d.filter), fu = rths::signal::SosAtRest(d.filter);
  Eigen::Vector4d theta = d.theta0, T = Eigen::Vector4d::Zero(), phi = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = d.P0;
  double y = 0.0, worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double target = Target(k);
    const double u = rths::control::RodeacStep(d, &s, target, y);
    // Independent: theta_k from u_f(u), then the residual of u - theta_k^T T_k must vanish.
    T = Eigen::Vector4d(target, T(0), T(1), T(2));  // newest first (a temporary: no aliasing)
    phi = Eigen::Vector4d(rths::signal::SosStep(d.filter, &fy, y), phi(0), phi(1), phi(2));
    const double uf = rths::signal::SosStep(d.filter, &fu, u);
    const Eigen::Vector4d K = P * phi / (1.0 + phi.dot(P * phi));
    theta = theta + K * (uf - phi.dot(theta));
    P = P - K * phi.transpose() * P;
    worst = std::max(worst, std::abs(u - theta.dot(T)) / (1.0 + std::abs(u)));
    CHECK((theta - s.theta).cwiseAbs().maxCoeff() < 1e-9);
    y = 0.8 * u;  // a static plant with gain 0.8, no delay
  }
  CHECK(worst < 1e-12);
}

TEST_CASE("on a static plant of gain 0.8 the taps converge to the inverse, 1.25 on the newest") {
  const auto d = Design(Eigen::Vector4d(0.9, 0.1, 0.0, 0.0), 1000.0);
  rths::control::RodeacState s = rths::control::RodeacAtRest(d);
  double y = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double u = rths::control::RodeacStep(d, &s, Target(k), y);
    y = 0.8 * u;
  }
  CHECK(s.theta(0) + s.theta(1) + s.theta(2) + s.theta(3) == doctest::Approx(1.25).epsilon(1e-3));
  CHECK(std::abs(y - 0.8 * 1.25 * Target(19999)) < 0.02);
}

TEST_CASE("a design is validated") {
  CHECK_THROWS_WITH(rths::control::MakeRodeacDesign(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Zero(), 30.0),
                    doctest::Contains("cutoff"));
  CHECK_THROWS_WITH(rths::control::MakeRodeacDesign(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Zero(), 1024.0, 1.5),
                    doctest::Contains("forgetting"));
}
