// The one Levenberg-Marquardt driver (ident/lm.h): the damped step under both fits' damping
// rules, the active set, held coordinates, LmIterate's forward-difference Jacobian on a problem
// whose constrained minimum is known.
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <doctest/doctest.h>

#include "ident/lm.h"

namespace {

using rths::ident::LmBox;
using rths::ident::LmDamping;
using Vec = Eigen::VectorXd;

struct Ev {
  Vec r;
  double cost = std::numeric_limits<double>::infinity();
};

/// r = theta - b: the minimum is b, clamped into the box.
Ev Residual(const Vec& theta, const Vec& b) {
  Ev e;
  e.r = theta - b;
  e.cost = e.r.squaredNorm();
  return e;
}

}  // namespace

TEST_CASE("LmIterate: the box's minimum of a separable problem, a coordinate held where it was put") {
  const Vec b = (Vec(3) << -1.0, 2.0, 7.0).finished();
  LmBox<Vec> box(3, [](int) { return 0.0; }, [](int) { return 10.0; });
  box.Hold(2, 5.0, "held for the test");
  CHECK(box.Held(2));
  CHECK(!box.Held(0));
  rths::ident::LmState<Vec, Ev> s;
  s.theta = (Vec(3) << 3.0, 3.0, 5.0).finished();
  s.ev = Residual(s.theta, b);
  int evaluations = 0;
  auto eval = [&](const Vec& t) {
    ++evaluations;
    return Residual(t, b);
  };
  rths::ident::LmIterate(
      &s, box, 50, eval, [&](const Vec& t, const Ev&, int) { return eval(t); }, eval, 1e-12, 1e-12);
  CHECK(s.converged);
  CHECK(s.iterations < 50);
  CHECK(s.theta[0] == doctest::Approx(0.0).epsilon(1e-9));  // wants -1: on its floor
  CHECK(s.theta[1] == doctest::Approx(2.0).epsilon(1e-6));
  CHECK(s.theta[2] == 5.0);                                  // held: never moved
  CHECK(s.ev.cost == doctest::Approx(1.0 + 4.0).epsilon(1e-6));
  CHECK(evaluations > 0);
}

TEST_CASE("DampedStep: the damper fits' rule refuses an equal cost and gives up at mu_max; Eq. 15's accepts it") {
  // At the minimum the gradient is zero: the step is zero and the trial's cost equals the current one.
  const Vec b = (Vec(2) << 1.0, 2.0).finished();
  const Vec lo = Vec::Constant(2, -10.0), hi = Vec::Constant(2, 10.0);
  const Eigen::MatrixXd H = Eigen::MatrixXd::Identity(2, 2);
  const Vec g = Vec::Zero(2);
  {
    Vec theta = b;
    Ev ev = Residual(theta, b);
    double mu = 1e-3;
    const auto step = rths::ident::DampedStep(H, g, &theta, &ev, &mu, [&](const Vec& t) { return Residual(t, b); },
                                              lo, hi);
    CHECK(!step.accepted);
    CHECK(mu >= 1e12);  // x4 until mu_max
  }
  {
    Vec theta = b;
    Ev ev = Residual(theta, b);
    double mu = 1e-3;
    const auto step = rths::ident::DampedStep(H, g, &theta, &ev, &mu, [&](const Vec& t) { return Residual(t, b); },
                                              lo, hi, rths::ident::PoleFitDamping());
    CHECK(step.accepted);
    CHECK(step.solved_norm == 0.0);
    CHECK(mu == doctest::Approx(1e-4));  // / 10
  }
}

TEST_CASE("DampedStep: a step that is not finite is skipped unevaluated (40 trials at most); the active set") {
  const Vec b = (Vec(2) << 1.0, 2.0).finished();
  const Vec lo = Vec::Constant(2, 0.0), hi = Vec::Constant(2, 10.0);
  const Eigen::MatrixXd H = Eigen::MatrixXd::Constant(2, 2, std::numeric_limits<double>::quiet_NaN());
  Vec theta = (Vec(2) << 3.0, 3.0).finished();
  Ev ev = Residual(theta, b);
  double mu = 1e-3;
  int evaluations = 0;
  const auto step = rths::ident::DampedStep(
      H, Vec::Ones(2), &theta, &ev, &mu,
      [&](const Vec& t) {
        ++evaluations;
        return Residual(t, b);
      },
      lo, hi, rths::ident::PoleFitDamping());
  CHECK(!step.accepted);
  CHECK(evaluations == 0);
  CHECK(mu == doctest::Approx(1e-3 * 1e40).epsilon(1e-9));
  // The active set: with r = J theta - b, J = [1 1; 0 1], b = (-2, 1), theta_0 >= 0, the minimum
  // is (0, -0.5). From (0, 3) theta_0 sits on its floor with the gradient pushing it outward: it
  // is taken out, and theta_1 takes its own Gauss-Newton step to -0.5. (The clamped full step
  // would land on (0, 1), at a cost of 9 against 4.5.)
  Eigen::MatrixXd J(2, 2);
  J << 1.0, 1.0, 0.0, 1.0;
  const Vec b2 = (Vec(2) << -2.0, 1.0).finished();
  auto coupled = [&](const Vec& t) {
    Ev e;
    e.r = J * t - b2;
    e.cost = e.r.squaredNorm();
    return e;
  };
  const Vec lo2 = (Vec(2) << 0.0, -10.0).finished(), hi2 = Vec::Constant(2, 10.0);
  Vec t2 = (Vec(2) << 0.0, 3.0).finished();
  Ev e2 = coupled(t2);
  double mu2 = 1e-9;
  const Eigen::MatrixXd H2 = J.transpose() * J;
  const Vec g2 = J.transpose() * e2.r;
  const auto s2 = rths::ident::DampedStep(H2, g2, &t2, &e2, &mu2, coupled, lo2, hi2);
  CHECK(s2.accepted);
  CHECK(t2[0] == 0.0);
  CHECK(t2[1] == doctest::Approx(-0.5).epsilon(1e-6));
  CHECK(e2.cost == doctest::Approx(4.5).epsilon(1e-6));
}
