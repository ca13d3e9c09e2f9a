// Central-difference integration of a linear structure (Eqs. 1-3) against closed forms.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <doctest/doctest.h>

#include "core/error.h"
#include "models/structure.h"

using namespace rths::models;

// Count every heap allocation of the process (Eigen and new end in malloc).
#include "alloc_counter.h"

namespace {

constexpr double kPi = std::numbers::pi;

Eigen::VectorXd Vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double e : v) x(i++) = e;
  return x;
}

// Max error of the damped SDOF free vibration from x0 = 10 mm, v0 = 0 over 2 s, against
// x(t) = e^{-zeta w t} (x0 cos wd t + zeta w x0 / wd sin wd t).
double FreeVibrationError(double dt) {
  const double f = 2.0, zeta = 0.05, x0 = 10.0;
  const CentralDifference cd =
      CentralDifference::Make(LinearStructure::Sdof(20000, f, zeta, 1), dt);
  StructureState s = MakeState(cd);
  SetInitialConditions(cd, &s, Vec({x0}), Vec({0.0}));
  const double w = 2 * kPi * f, wd = w * std::sqrt(1 - zeta * zeta);
  double err = 0.0;
  const int steps = static_cast<int>(std::lround(2.0 / dt));
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    const double exact =
        std::exp(-zeta * w * t) * (x0 * std::cos(wd * t) + zeta * w * x0 / wd * std::sin(wd * t));
    err = std::max(err, std::abs(s.x(0) - exact));
    Advance(cd, &s, 0.0, 0.0);
  }
  return err;
}

}  // namespace

TEST_CASE("SDOF in project units") {
  const LinearStructure s = LinearStructure::Sdof(20000.0, 5.0, 0.02, 18.0);
  const double m = 0.02, w = 10 * kPi;  // kN s^2/mm, rad/s
  CHECK(s.M(0, 0) == doctest::Approx(m));
  CHECK(s.K(0, 0) == doctest::Approx(m * w * w));  // 19.74 kN/mm
  CHECK(s.C(0, 0) == doctest::Approx(2 * 0.02 * m * w));
  CHECK(s.specimen_dir(0) == 18.0);
  CHECK(s.iota(0) == 1.0);
  CHECK_THROWS_AS(LinearStructure::Sdof(0.0, 5.0, 0.02, 1.0), rths::Error);
  CHECK_THROWS_AS(LinearStructure::Sdof(1.0, 5.0, 1.0, 1.0), rths::Error);
  CHECK_THROWS_AS(LinearStructure::Sdof(1.0, 5.0, 0.02, -1.0), rths::Error);
  // specimen_count = 0 (issue 44's reference case): the specimen's force does not act.
  CHECK(LinearStructure::Sdof(1.0, 5.0, 0.02, 0.0).specimen_dir(0) == 0.0);
}

TEST_CASE("free vibration of a damped SDOF: second-order convergence to the closed form") {
  const double T = 0.5;
  const double e1 = FreeVibrationError(T / 50), e2 = FreeVibrationError(T / 100),
               e3 = FreeVibrationError(T / 200);
  const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e3);
  MESSAGE("max errors " << e1 << ", " << e2 << ", " << e3 << " mm; orders " << order1 << ", "
                        << order2);
  CHECK(order1 == doctest::Approx(2.0).epsilon(0.05));
  CHECK(order2 == doctest::Approx(2.0).epsilon(0.05));
  CHECK(e3 < 1e-3 * 10.0);
}

TEST_CASE("harmonic ground acceleration: steady-state amplitude, phase, velocity, acceleration") {
  // x'' + 2 zeta w x' + w^2 x = -a_g, a_g = A sin(W t): x = -X sin(W t - phi),
  // X = A / sqrt((w^2 - W^2)^2 + (2 zeta w W)^2), phi = atan2(2 zeta w W, w^2 - W^2).
  const double f = 5.0, zeta = 0.05, fg = 3.0, A = 1000.0, dt = 0.0005;
  const CentralDifference cd =
      CentralDifference::Make(LinearStructure::Sdof(20000, f, zeta, 1), dt);
  StructureState s = MakeState(cd);
  const double w = 2 * kPi * f, W = 2 * kPi * fg;
  const double X = A / std::hypot(w * w - W * W, 2 * zeta * w * W);
  const double phi = std::atan2(2 * zeta * w * W, w * w - W * W);
  const int steps = 20000, fit_from = 16000;  // 10 s; fit over the last 2 s (6 periods)
  double a = 0.0, b = 0.0, max_dv = 0.0, max_da = 0.0, max_dabs = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt, ag = A * std::sin(W * t);
    if (k >= fit_from) {
      a += 2.0 / (steps - fit_from) * s.x(0) * std::sin(W * t);
      b += 2.0 / (steps - fit_from) * s.x(0) * std::cos(W * t);
    }
    Advance(cd, &s, ag, 0.0);
    if (k >= fit_from) {  // velocity and accelerations at t_k
      const double v = -X * W * std::cos(W * t - phi), acc = X * W * W * std::sin(W * t - phi);
      max_dv = std::max(max_dv, std::abs(s.vel_prev(0) - v));
      max_da = std::max(max_da, std::abs(s.acc_prev(0) - acc));
      max_dabs = std::max(max_dabs, std::abs(s.abs_acc_prev(0) - (acc + ag)));
    }
  }
  // x = -X (sin Wt cos phi - cos Wt sin phi): a = -X cos phi, b = X sin phi.
  const double amp = std::hypot(a, b), ph = std::atan2(b, -a);
  MESSAGE("amplitude " << amp << " mm (closed form " << X << "), phase " << ph * 180 / kPi
                       << " deg (" << phi * 180 / kPi << ")");
  CHECK(amp == doctest::Approx(X).epsilon(1e-4));
  CHECK(std::abs(ph - phi) < 1e-4);  // rad
  CHECK(max_dv < 2e-3 * X * W);
  CHECK(max_da < 2e-3 * X * W * W);
  CHECK(max_dabs < 2e-3 * X * W * W);
}

TEST_CASE("specimen force resists: a constant force f gives x = -K^-1 s f at rest") {
  Eigen::MatrixXd M(2, 2), K(2, 2);
  M << 0.02, 0, 0, 0.01;
  K << 30, -10, -10, 10;
  const Eigen::MatrixXd C = 5.0 * M + 0.001 * K;  // heavily damped
  const LinearStructure st = LinearStructure::Make(M, C, K, 0, 18.0);
  const CentralDifference cd = CentralDifference::Make(st, 0.001);
  StructureState s = MakeState(cd);
  const double ag = 500.0, f = 2.0;  // mm/s^2, kN
  for (int k = 0; k < 20000; ++k) Advance(cd, &s, ag, f);
  // K x = -M iota a_g - s f, solved by hand: rhs = [-10 - 36, -5]; K^-1 = [[1, 1], [1, 3]] / 20.
  const double r0 = -0.02 * ag - 18.0 * f, r1 = -0.01 * ag;
  CHECK(s.x(0) == doctest::Approx((r0 + r1) / 20.0).epsilon(1e-6));
  CHECK(s.x(1) == doctest::Approx((r0 + 3 * r1) / 20.0).epsilon(1e-6));
  CHECK(s.x(0) < 0.0);                                  // pushed back by a positive force
  CHECK(std::abs(s.abs_acc_prev(0) - ag) < 1e-6 * ag);  // at rest it moves with the ground
}

TEST_CASE("stability limit dt < T/pi") {
  const double f = 10.0, T = 1.0 / f, limit = T / kPi;
  const LinearStructure st = LinearStructure::Sdof(20000, f, 0.0, 1);
  auto run = [&](double dt, int steps) {
    const CentralDifference cd = CentralDifference::Make(st, dt, false);
    StructureState s = MakeState(cd);
    SetInitialConditions(cd, &s, Vec({1.0}), Vec({0.0}));
    double peak = 0.0;
    for (int k = 0; k < steps; ++k) {
      Advance(cd, &s, 0.0, 0.0);
      peak = std::max(peak, std::abs(s.x(0)));
    }
    return peak;
  };
  // Undamped with this start, x_k = x0 cos(w~ k dt) exactly: bounded by x0 for ever.
  CHECK(run(0.99 * limit, 100000) < 1.0 + 1e-6);
  // Just above: |lambda| = 1.33 per step for w dt = 2.02.
  CHECK(run(1.01 * limit, 100) > 1e9);

  const CentralDifference ok = CentralDifference::Make(st, 0.99 * limit);
  CHECK(ok.dt_limit_s == doctest::Approx(limit).epsilon(1e-12));
  CHECK(ok.max_frequency_hz == doctest::Approx(f).epsilon(1e-12));
  CHECK_THROWS_WITH_AS(CentralDifference::Make(st, 1.000001 * limit),
                       doctest::Contains("stability limit T_min/pi = 0.031831 s"), rths::Error);
  CHECK_THROWS_WITH_AS(CentralDifference::Make(st, 1.000001 * limit),
                       doctest::Contains("highest natural frequency 10 Hz"), rths::Error);
  CHECK_THROWS_AS(CentralDifference::Make(st, 0.0), rths::Error);
}

TEST_CASE("2-DOF free vibration against an independent modal solution") {
  // M = diag(0.02, 0.01), K = [[30, -10], [-10, 10]]: det(K - l M) = 2e-4 l^2 - 0.5 l + 200,
  // l = 500 (mode [1, 2]) and 2000 (mode [1, -1]). Rayleigh damping C = a M + b K keeps the
  // modes uncoupled: zeta_i = a / (2 w_i) + b w_i / 2.
  Eigen::MatrixXd M(2, 2), K(2, 2);
  M << 0.02, 0, 0, 0.01;
  K << 30, -10, -10, 10;
  const double ra = 0.3, rb = 0.0004;
  const LinearStructure st = LinearStructure::Make(M, ra * M + rb * K, K, 1, 1.0);
  const double w[2] = {std::sqrt(500.0), std::sqrt(2000.0)};
  const double phi[2][2] = {{1, 2}, {1, -1}};  // phi[mode][dof]
  const Eigen::VectorXd x0 = Vec({1.0, 3.0}), v0 = Vec({0.0, 10.0});
  // Modal coordinates: x = q1 [1, 2] + q2 [1, -1] => q1 = (x1 + x2) / 3, q2 = (2 x1 - x2) / 3.
  const double q0[2] = {(x0(0) + x0(1)) / 3, (2 * x0(0) - x0(1)) / 3};
  const double qv0[2] = {(v0(0) + v0(1)) / 3, (2 * v0(0) - v0(1)) / 3};
  auto exact = [&](double t, int dof) {
    double x = 0.0;
    for (int i = 0; i < 2; ++i) {
      const double z = ra / (2 * w[i]) + rb * w[i] / 2, wd = w[i] * std::sqrt(1 - z * z);
      const double q =
          std::exp(-z * w[i] * t) *
          (q0[i] * std::cos(wd * t) + (qv0[i] + z * w[i] * q0[i]) / wd * std::sin(wd * t));
      x += phi[i][dof] * q;
    }
    return x;
  };
  const double dt = 0.00025;
  const CentralDifference cd = CentralDifference::Make(st, dt);
  CHECK(cd.max_frequency_hz == doctest::Approx(w[1] / (2 * kPi)).epsilon(1e-10));
  StructureState s = MakeState(cd);
  SetInitialConditions(cd, &s, x0, v0);
  double err = 0.0, peak = 0.0;
  for (int k = 0; k < 20000; ++k) {  // 5 s
    for (int d = 0; d < 2; ++d) {
      err = std::max(err, std::abs(s.x(d) - exact(k * dt, d)));
      peak = std::max(peak, std::abs(s.x(d)));
    }
    Advance(cd, &s, 0.0, 0.0);
  }
  MESSAGE("2-DOF max error " << err << " mm of a " << peak << " mm response");
  CHECK(err < 2e-4 * peak);
}

TEST_CASE("Advance allocates nothing") {
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(9, 9) * 0.5, K = Eigen::MatrixXd::Zero(9, 9);
  for (int i = 0; i < 9; ++i) {  // a 9-story shear chain, 200 kN/mm per story
    K(i, i) += 200;
    if (i + 1 < 9) K(i, i) += 200, K(i, i + 1) = K(i + 1, i) = -200;
  }
  const CentralDifference cd =
      CentralDifference::Make(LinearStructure::Make(M, 0.01 * K, K, 0, 18), 0.0005);
  StructureState s = MakeState(cd);
  const long before = rths_test::AllocationCount();
  for (int k = 0; k < 1000; ++k) Advance(cd, &s, 100.0 * std::sin(0.01 * k), 1.0);
  CHECK(rths_test::AllocationCount() - before == 0);
  CHECK(s.k == 1000);
  CHECK(s.x.allFinite());
}

TEST_CASE("Make validates the matrices") {
  Eigen::MatrixXd M(2, 2), K(2, 2);
  M << 0.02, 0, 0, 0.01;
  K << 30, -10, -10, 10;
  CHECK_THROWS_AS(LinearStructure::Make(M, M, K, 2, 1.0), rths::Error);
  CHECK_THROWS_AS(LinearStructure::Make(-M, M, K, 0, 1.0), rths::Error);
  CHECK_THROWS_AS(LinearStructure::Make(M, Eigen::MatrixXd::Zero(3, 3), K, 0, 1.0), rths::Error);
  Eigen::MatrixXd Kn = K;
  Kn(0, 1) = -5;
  CHECK_THROWS_AS(LinearStructure::Make(M, M, Kn, 0, 1.0), rths::Error);
}
