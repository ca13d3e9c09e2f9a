// Tests for lib/control/feedforward: coefficients (Eq. 17, docs/models.md section 2), derivative
// extrapolation (Eqs. 20-22) against Taylor-series closed forms, central differences, Eq. 19.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <new>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "control/feedforward.h"
#include "core/error.h"
#include "scenario/scenario.h"

namespace ctl = rths::control;
using rths::models::ServoModel3;
using std::numbers::pi;

#include "alloc_counter.h"

namespace {

// Eqs. 28-30 (docs/models.md section 1).
ServoModel3 Model(double K, double p, double b, double c, const char* name) {
  ServoModel3 m;
  m.K = K;
  m.p = p;
  m.b = b;
  m.c = c;
  m.name = name;
  return m;
}
const ServoModel3 kModel00 = Model(1.730e7, 182.7, 225.3, 9.499e4, "0.0A");
const ServoModel3 kModel25 = Model(1.613e7, 134.2, 324.6, 1.211e5, "2.5A");
const ServoModel3 kModelAvg = Model(1.600e7, 151.7, 250.4, 1.061e5, "avg");

std::complex<double> G(const ServoModel3& m, std::complex<double> s) {
  return m.K / ((s + m.p) * (s * s + m.b * s + m.c));
}
std::complex<double> Gff(const ctl::FeedforwardCoefficients& a, std::complex<double> s) {
  return a.a0 + s * (a.a1 + s * (a.a2 + s * a.a3));
}

}  // namespace

TEST_CASE("feedforward: coefficients match docs/models.md section 2") {
  struct Case {
    const ServoModel3* m;
    double a0, a1, a2, a3;
  };
  const Case cases[] = {
      {&kModel00, 1.003160, 7.870076e-3, 2.358382e-5, 5.780347e-8},
      {&kModel25, 1.007540, 1.020839e-2, 2.844389e-5, 6.199628e-8},
      {&kModelAvg, 1.005961, 9.005355e-3, 2.513125e-5, 6.250000e-8},
  };
  for (const Case& c : cases) {
    CAPTURE(c.m->name);
    const auto a = ctl::MakeFeedforwardCoefficients(*c.m);
    // The reference values have 7 significant digits.
    CHECK(a.a0 == doctest::Approx(c.a0).epsilon(1e-6));
    CHECK(a.a1 == doctest::Approx(c.a1).epsilon(1e-6));
    CHECK(a.a2 == doctest::Approx(c.a2).epsilon(1e-6));
    CHECK(a.a3 == doctest::Approx(c.a3).epsilon(1e-6));
    // G_FF is the exact inverse of G (Eq. 16): G_FF(jw) G(jw) = 1 at every frequency.
    for (double f : {0.0, 1.0, 10.0, 50.0, 300.0}) {
      const std::complex<double> s(0.0, 2.0 * pi * f);
      const auto prod = Gff(a, s) * G(*c.m, s);
      CHECK(prod.real() == doctest::Approx(1.0).epsilon(1e-12));
      CHECK(std::abs(prod.imag()) < 1e-12);
    }
  }
}

TEST_CASE("feedforward: coefficient preconditions name the parameter") {
  for (const char* name : {"K", "p", "b", "c"}) {
    ServoModel3 m = kModelAvg;
    double* field = std::string(name) == "K" ? &m.K : std::string(name) == "p" ? &m.p
                                             : std::string(name) == "b" ? &m.b
                                                                        : &m.c;
    for (double bad : {0.0, -1.0, std::nan("")}) {
      *field = bad;
      try {
        ctl::MakeFeedforwardCoefficients(m);
        FAIL("expected rths::Error for ", name, " = ", bad);
      } catch (const rths::Error& e) {
        CHECK(e.problem().rfind(std::string(name) + " =", 0) == 0);
      }
    }
  }
}

TEST_CASE("extrapolation: at rest, the state is zero and a zero trajectory has zero derivatives") {
  ctl::ExtrapolationState st;
  for (int i = 0; i < 5; ++i) {
    const auto d = ctl::StepDerivatives(&st, 0.0, 0.0005);
    CHECK(d.r == 0.0);
    CHECK(d.rd == 0.0);
    CHECK(d.rdd == 0.0);
    CHECK(d.rddd == 0.0);
  }
  // First step from rest: r_{-1} = r_{-2} = r_{-3} = 0.
  const double dt = 0.01;
  const auto d = ctl::ExtrapolateDerivatives(ctl::ExtrapolationState{}, 1.0, dt);
  CHECK(d.acc_prev == doctest::Approx(1.0 / (dt * dt)));
  CHECK(d.vel_prev == doctest::Approx(1.0 / (2 * dt)));
}

TEST_CASE("extrapolation: Eqs. 20-22 on a cubic") {
  // For a cubic r(t) = c0 + c1 t + c2 t^2 + c3 t^3, r'' is linear and r''' constant, and:
  //  - a_{i-1}, a_{i-2} (central second differences) are exact: their error is dt^2/12 r'''' = 0;
  //  - hence the linear extrapolation of r'' (Eq. 20) and the slope r''' (Eq. 22) are exact;
  //  - in Eq. 21 the trapezoid dt/2 (a_{i-1} + r''_i) integrates the linear r'' exactly, but
  //    v_{i-1} = (r_i - r_{i-2}) / (2 dt) is a central difference with error dt^2/6 r''' = c3 dt^2,
  //    so r'_i = r'(t_i) + c3 dt^2 (exact only up to quadratics).
  const double c0 = 0.3, c1 = -2.0, c2 = 40.0, c3 = 1000.0;
  const auto r = [&](double t) { return c0 + t * (c1 + t * (c2 + t * c3)); };
  const auto rd = [&](double t) { return c1 + t * (2 * c2 + t * 3 * c3); };
  const auto rdd = [&](double t) { return 2 * c2 + 6 * c3 * t; };
  for (double dt : {0.01, 0.0005}) {
    CAPTURE(dt);
    ctl::ExtrapolationState st;
    for (int i = -3; i < 0; ++i) ctl::PushDisplacement(&st, r(i * dt));
    for (int i = 0; i < 60; ++i) {
      const double t = i * dt;
      const ctl::ExtrapolationState before = st;
      const auto d = ctl::StepDerivatives(&st, r(t), dt);
      // The pure function gives the same answer from the pre-step state (re-answering a step).
      const auto again = ctl::ExtrapolateDerivatives(before, r(t), dt);
      CHECK(again.rdd == d.rdd);
      CHECK(st.r1 == r(t));
      CHECK(st.r2 == before.r1);
      CHECK(st.r3 == before.r2);

      CHECK(d.r == r(t));
      CHECK(d.rdd == doctest::Approx(rdd(t)).epsilon(1e-7));
      CHECK(d.rddd == doctest::Approx(6 * c3).epsilon(1e-6));
      CHECK(d.rd == doctest::Approx(rd(t) + c3 * dt * dt).epsilon(1e-9));
      CHECK(d.acc_prev == doctest::Approx(rdd(t - dt)).epsilon(1e-7));
      CHECK(d.vel_prev == doctest::Approx(rd(t - dt) + c3 * dt * dt).epsilon(1e-9));
    }
  }
  // A quadratic: r' is exact too.
  ctl::ExtrapolationState st;
  const double dt = 0.01;
  const auto q = [](double t) { return 1.0 - 3.0 * t + 25.0 * t * t; };
  for (int i = -3; i < 0; ++i) ctl::PushDisplacement(&st, q(i * dt));
  for (int i = 0; i < 20; ++i) {
    const auto d = ctl::StepDerivatives(&st, q(i * dt), dt);
    CHECK(d.rd == doctest::Approx(-3.0 + 50.0 * i * dt).epsilon(1e-10));
    CHECK(d.rdd == doctest::Approx(50.0).epsilon(1e-8));
    CHECK(std::abs(d.rddd) < 1e-4);
  }
}

TEST_CASE("extrapolation: convergence on a sine at the leading-order Taylor rates") {
  // r = A sin(w t). Taylor expansion of Eqs. 20-22 (h = dt):
  //   r''_i   - r''(t_i)   = -(11/12) h^2 r''''   -> max 11/12 h^2 A w^4   (second order)
  //   r'''_i  - r'''(t_i)  = -(3/2) h r''''        -> max 3/2 h A w^4       (first order)
  //   r'_i    - r'(t_i)    = h^2/6 r''' + O(h^3)   -> max h^2/6 A w^3       (second order)
  const double A = 2.0, w = 2.0 * pi * 10.0;
  for (double dt : {0.001, 0.0005, 0.00025}) {
    CAPTURE(dt);
    ctl::ExtrapolationState st;
    for (int i = -3; i < 0; ++i) ctl::PushDisplacement(&st, A * std::sin(w * i * dt));
    double e1 = 0, e2 = 0, e3 = 0;
    const int n = static_cast<int>(std::lround(1.0 / dt));
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      const auto d = ctl::StepDerivatives(&st, A * std::sin(w * t), dt);
      e1 = std::max(e1, std::abs(d.rd - A * w * std::cos(w * t)));
      e2 = std::max(e2, std::abs(d.rdd + A * w * w * std::sin(w * t)));
      e3 = std::max(e3, std::abs(d.rddd + A * w * w * w * std::cos(w * t)));
    }
    CHECK(e1 == doctest::Approx(dt * dt / 6.0 * A * w * w * w).epsilon(0.05));
    CHECK(e2 == doctest::Approx(11.0 / 12.0 * dt * dt * A * std::pow(w, 4)).epsilon(0.05));
    CHECK(e3 == doctest::Approx(1.5 * dt * A * std::pow(w, 4)).epsilon(0.10));
  }
}

TEST_CASE("central derivatives: exactness orders and zero-padded ends") {
  // Truncation errors: r' central h^2/6 r''', r'' central h^2/12 r'''', r''' five-point
  // h^2/4 r^(5). On a quartic c0 + ... + c4 t^4: r''' exact, r'' off by 2 c4 h^2,
  // r' off by h^2/6 (6 c3 + 24 c4 t).
  const double c0 = 0.5, c1 = 1.0, c2 = -30.0, c3 = 200.0, c4 = 4000.0, dt = 0.01;
  const std::size_t n = 50;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i * dt;
    r[i] = c0 + t * (c1 + t * (c2 + t * (c3 + t * c4)));
  }
  const auto d = ctl::CentralDerivatives(r, dt);
  REQUIRE(d.rd.size() == n);
  REQUIRE(d.rdd.size() == n);
  REQUIRE(d.rddd.size() == n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i * dt;
    CAPTURE(i);
    if (i >= 1 && i + 1 < n) {
      const double r1 = c1 + t * (2 * c2 + t * (3 * c3 + t * 4 * c4));
      const double r2 = 2 * c2 + t * (6 * c3 + t * 12 * c4);
      CHECK(d.rd[i] == doctest::Approx(r1 + dt * dt / 6.0 * (6 * c3 + 24 * c4 * t)).epsilon(1e-9));
      CHECK(d.rdd[i] == doctest::Approx(r2 + 2 * c4 * dt * dt).epsilon(1e-8));
    } else {
      CHECK(d.rd[i] == 0.0);
      CHECK(d.rdd[i] == 0.0);
    }
    if (i >= 2 && i + 2 < n) {
      CHECK(d.rddd[i] == doctest::Approx(6 * c3 + 24 * c4 * t).epsilon(1e-6));
    } else {
      CHECK(d.rddd[i] == 0.0);
    }
  }
  const auto at = d.At(r, 10);
  CHECK(at.r == r[10]);
  CHECK(at.rddd == d.rddd[10]);
  CHECK_THROWS_AS(ctl::CentralDerivatives(r, 0.0), rths::Error);
  CHECK(ctl::CentralDerivatives({}, 0.001).rd.empty());
}

TEST_CASE("feedforward command: Eq. 19 is G_FF(jw) applied to a sine") {
  // With the exact derivatives of r = A sin(w t), Eq. 19 gives u = A Im(G_FF(jw) e^{jwt}),
  // which the model maps back to r: G(jw) G_FF(jw) = 1.
  const auto a = ctl::MakeFeedforwardCoefficients(kModelAvg);
  const double A = 1.5, dt = 0.0005;
  for (double f : {1.0, 10.0, 30.0}) {
    const double w = 2.0 * pi * f;
    const std::complex<double> gff = Gff(a, {0.0, w});
    const auto exact = [&](double t) {
      return ctl::Derivatives{A * std::sin(w * t), A * w * std::cos(w * t), -A * w * w * std::sin(w * t),
                              -A * w * w * w * std::cos(w * t), 0.0, 0.0};
    };
    for (double t : {0.0, 0.013, 0.2}) {
      CAPTURE(f);
      CAPTURE(t);
      const double u = ctl::FeedforwardCommand(a, exact(t), false, dt);
      const double expect = A * std::imag(gff * std::polar(1.0, w * t));
      CHECK(u == doctest::Approx(expect).epsilon(1e-12).scale(A * std::abs(gff)));
      // Half a step ahead: u(t) + dt/2 u'(t) except the a3 term; so it is u(t + dt/2) to within
      // a3 (dt/2) r'''' + O(dt^2) -- much closer to u(t + dt/2) than u(t) is.
      const double u_half = ctl::FeedforwardCommand(a, exact(t), true, dt);
      const double u_ahead = A * std::imag(gff * std::polar(1.0, w * (t + dt / 2)));
      const double bound = a.a3 * dt / 2 * A * std::pow(w, 4) +
                           (dt * dt / 8) * A * (a.a0 * w * w + a.a1 * w * w * w + a.a2 * std::pow(w, 4) + a.a3 * std::pow(w, 5)) +
                           1e-12;
      CHECK(std::abs(u_half - u_ahead) <= bound);
      CHECK(u_half == doctest::Approx(u + dt / 2 * (a.a0 * exact(t).rd + a.a1 * exact(t).rdd +
                                                    a.a2 * exact(t).rddd))
                          .epsilon(1e-12)
                          .scale(A * std::abs(gff)));
    }
  }
}

TEST_CASE("per-step functions allocate nothing") {
  const auto a = ctl::MakeFeedforwardCoefficients(kModelAvg);
  ctl::ExtrapolationState st;
  double sink = 0.0;
  const long before = rths_test::AllocationCount();
  for (int i = 0; i < 1000; ++i) {
    const auto d = ctl::StepDerivatives(&st, std::sin(0.01 * i), 0.0005);
    sink += ctl::FeedforwardCommand(a, d, false, 0.0005) + ctl::FeedforwardCommand(a, d, true, 0.0005);
  }
  const long after = rths_test::AllocationCount();
  CHECK(after == before);
  CHECK(std::isfinite(sink));
}
