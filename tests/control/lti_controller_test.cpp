// Tests for the `lti` controller (lib/control/transfer_function.h, lti_controller.h): discretisation
// against known discrete equivalents (bit for bit where the arithmetic is exact), MATLAB's `filter`
// recursion, stability judgement and the refusals that name the scenario key, output limits, the
// linear maps used by `rths design`, allocation-free steps, and the scenario keys.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "control/analysis.h"
#include "control/design.h"
#include "control/lti_controller.h"
#include "control/transfer_function.h"
#include "core/error.h"
#include "scenario/scenario.h"
#include "signal/blwn.h"

#include "alloc_counter.h"
#include "scenario_support.h"
#include "test_support.h"

namespace ctl = rths::control;
using cd = std::complex<double>;

namespace {

constexpr double kDt = 1.0 / 4096.0;  // the benchmark's rate: 2/dt = 8192 = 2^13 (exact arithmetic)

ctl::LtiConfig Lti(ctl::TfCoefficients c, ctl::TfCoefficients t = {}) {
  ctl::LtiConfig cfg;
  cfg.feedback = std::move(c);
  cfg.reference = std::move(t);
  return cfg;
}

/// MATLAB's filter(b, a, x) with a(1) = 1, written out independently (transposed direct form II).
std::vector<double> MatlabFilter(const std::vector<double>& b, const std::vector<double>& a,
                                 const std::vector<double>& x) {
  const std::size_t n = a.size() - 1;
  std::vector<double> z(n + 1, 0.0), y(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    y[k] = b[0] * x[k] + z[0];
    for (std::size_t j = 1; j < n; ++j) z[j - 1] = b[j] * x[k] + z[j] - a[j] * y[k];
    if (n > 0) z[n - 1] = b[n] * x[k] - a[n] * y[k];
  }
  return y;
}

std::string ErrorOf(const ctl::LtiConfig& cfg) {
  try {
    ctl::MakeLtiDesign(cfg, kDt);
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Tustin: the benchmark's PI 2 + 95/s and lead 50.8 (s + 168.6)/(s + 8570), as printed by MATLAB") {
  const ctl::LtiDesign d = ctl::MakeLtiDesign(
      Lti({{2.0, 95.0}, {1.0, 0.0}}, {{50.83163360273612, 8570.397339444286}, {1.0, 8570.397339444286}}), kDt);
  // PI: Kp + Ki (dt/2) (1 + z^-1)/(1 - z^-1); with 2/dt = 2^13 every operation is exact.
  const ctl::DiscreteTf& c = d.feedback.discrete;
  REQUIRE(c.order() == 1);
  CHECK(c.b[0] == 2.0 + 95.0 * kDt / 2.0);  // 2.0115966796875 exactly
  CHECK(c.b[1] == 95.0 * kDt / 2.0 - 2.0);  // -1.9884033203125 exactly
  CHECK(c.a[1] == -1.0);
  CHECK(d.feedback.stability.integrators == 1);
  CHECK(d.feedback.stability.Stable());
  // Lead: b0 = (K c + K z0)/(c + p), b1 = (K z0 - K c)/(c + p), a1 = (p - c)/(c + p), c = 2/dt.
  const double cc = 2.0 / kDt, k1 = 50.83163360273612, k0 = 8570.397339444286, p = 8570.397339444286;
  const ctl::DiscreteTf& t = d.reference.discrete;
  CHECK(t.b[0] == doctest::Approx((k1 * cc + k0) / (cc + p)).epsilon(1e-15));
  CHECK(t.b[1] == doctest::Approx((k0 - k1 * cc) / (cc + p)).epsilon(1e-15));
  CHECK(t.a[1] == doctest::Approx((p - cc) / (cc + p)).epsilon(1e-15));
  // The values the benchmark's c2dm(..., 'tustin') gives (8 digits, docs/benchmark.md).
  CHECK(t.b[0] == doctest::Approx(25.35336272).epsilon(1e-9));
  CHECK(t.b[1] == doctest::Approx(-24.33078854).epsilon(1e-9));
  CHECK(t.a[1] == doctest::Approx(0.02257418).epsilon(1e-6));
  CHECK(std::abs(t.Response(0.0) - 1.0) < 1e-12);  // DC gain 1
}

TEST_CASE("Tustin of a first-order section is bit for bit the textbook formula at 2/dt = 2^13") {
  const double a = 168.5, b = 4000.25, cc = 8192.0;
  const ctl::DiscreteTf h = ctl::TustinTf(ctl::CheckTf({{1.0, a}, {1.0, b}}, "k"), kDt);
  CHECK(h.b[0] == (cc + a) / (cc + b));
  CHECK(h.b[1] == (a - cc) / (cc + b));
  CHECK(h.a[0] == 1.0);
  CHECK(h.a[1] == (b - cc) / (cc + b));
}

TEST_CASE("ZOH: 1/(s + a) exactly, and a third-order model against the servo model's own ZOH") {
  const double a = 300.0;
  const ctl::DiscreteTf h = ctl::ZohTf(ctl::CheckTf({{1.0}, {1.0, a}}, "k"), kDt);
  REQUIRE(h.order() == 1);
  CHECK(h.b[0] == 0.0);
  CHECK(h.b[1] == doctest::Approx((1.0 - std::exp(-a * kDt)) / a).epsilon(1e-12));
  CHECK(h.a[1] == doctest::Approx(-std::exp(-a * kDt)).epsilon(1e-13));
  // K / ((s + p)(s^2 + b s + c)) = K / (s^3 + (p + b) s^2 + (p b + c) s + p c), Eq. 30's model.
  const rths::models::ServoModel3 m = rths::models::ServoPreset("avg");
  const ctl::DiscreteTf g = ctl::ZohTf(
      ctl::CheckTf({{m.K}, {1.0, m.p + m.b, m.p * m.b + m.c, m.p * m.c}}, "k"), 0.0005);
  const ctl::DiscreteSs ref = ctl::ServoZoh(m, 0.0005);
  for (double f : {0.5, 2.0, 10.0, 50.0, 200.0, 900.0}) {
    CAPTURE(f);
    CHECK(std::abs(g.Response(f) - ref.Response(f)) < 1e-9 * std::abs(ref.Response(f)));
  }
  // A PI by ZOH: (2 s + 95)/s -> 2 + 95 dt z^-1/(1 - z^-1).
  const ctl::DiscreteTf pi = ctl::ZohTf(ctl::CheckTf({{2.0, 95.0}, {1.0, 0.0}}, "k"), kDt);
  CHECK(pi.b[0] == doctest::Approx(2.0).epsilon(1e-14));
  CHECK(pi.b[1] == doctest::Approx(95.0 * kDt - 2.0).epsilon(1e-14));
  CHECK(pi.a[1] == -1.0);
}

TEST_CASE("domain z: coefficients as tfdata(c2d(...)) prints them; the controller runs MATLAB's filter bit for bit") {
  ctl::LtiConfig cfg = Lti({{0.0, 0.0121, 0.0119}, {1.0, -1.8, 0.81}}, {{1.5, -0.25}, {1.0, 0.3}});
  cfg.domain = ctl::TfDomain::kZ;
  const ctl::LtiDesign d = ctl::MakeLtiDesign(cfg, kDt);
  CHECK(d.feedback.discrete.b == std::vector<double>{0.0, 0.0121, 0.0119});
  CHECK(d.feedback.discrete.a == std::vector<double>{1.0, -1.8, 0.81});
  // A denominator that is not monic is divided through, as filter() does.
  ctl::LtiConfig scaled = cfg;
  scaled.feedback = {{0.0, 0.0242, 0.0238}, {2.0, -3.6, 1.62}};
  CHECK(ctl::MakeLtiDesign(scaled, kDt).feedback.discrete.a == std::vector<double>{1.0, -1.8, 0.81});

  const std::vector<double> r = rths::signal::Blwn(20.0, 1.0, kDt, 4000, 3, 0.1);
  std::vector<double> y(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) y[k] = 0.8 * (k >= 5 ? r[k - 5] : 0.0) + 0.01 * std::sin(0.3 * k);
  ctl::LtiController c(d);
  std::vector<double> u(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) u[k] = c.Step({r[k], 0, 0, 0}, {y[k], 0, 0}).u_mm;
  // Independently: t = filter(bT, aT, r); e = t - y; u = filter(bC, aC, e).
  const std::vector<double> t = MatlabFilter({1.5, -0.25}, {1.0, 0.3}, r);
  std::vector<double> e(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) e[k] = t[k] - y[k];
  const std::vector<double> expected = MatlabFilter({0.0, 0.0121, 0.0119}, {1.0, -1.8, 0.81}, e);
  std::size_t identical = 0;
  for (std::size_t k = 0; k < r.size(); ++k) identical += u[k] == expected[k];
  CHECK(identical == r.size());
}

TEST_CASE("u_ff + u_fb = u; u_fb is C (r - y); a missing transfer function is 1") {
  const ctl::LtiDesign d = ctl::MakeLtiDesign(Lti({{2.0, 95.0}, {1.0, 0.0}}, {{2.0, 10.0}, {1.0, 20.0}}), kDt);
  ctl::LtiState s, plain;
  for (int k = 0; k < 200; ++k) {
    const double r = std::sin(0.01 * k), y = 0.9 * std::sin(0.01 * (k - 3));
    const ctl::Command cmd = ctl::LtiStep(d, &s, r, y);
    CHECK(cmd.u_ff_mm + cmd.u_fb_mm == doctest::Approx(cmd.u_mm).epsilon(1e-12));
    CHECK(cmd.u_fb_mm == ctl::FilterStep(d.feedback.discrete, &plain.feedback, r - y));
  }
  // No tables at all: u = r - y.
  const ctl::LtiDesign unit = ctl::MakeLtiDesign(ctl::LtiConfig{}, kDt);
  ctl::LtiState s1;
  CHECK(ctl::LtiStep(unit, &s1, 3.0, 1.25).u_mm == 1.75);
}

TEST_CASE("saturation and rate limit act on the output; the integrator keeps integrating") {
  ctl::LtiConfig cfg = Lti({{2.0, 95.0}, {1.0, 0.0}});
  cfg.saturation_mm = 1.0;
  cfg.rate_limit_mm_s = 100.0;  // 0.0244 mm per step
  const ctl::LtiDesign d = ctl::MakeLtiDesign(cfg, kDt);
  ctl::LtiState s;
  double prev = 0.0, peak = 0.0;
  for (int k = 0; k < 4096; ++k) {
    const double u = ctl::LtiStep(d, &s, 5.0, 0.0).u_mm;  // a 5 mm step error: the PI demands far more
    CHECK(std::abs(u - prev) <= 100.0 * kDt * (1 + 1e-12));
    peak = std::max(peak, std::abs(u));
    prev = u;
  }
  CHECK(peak == 1.0);
  CHECK(std::abs(s.feedback.w[0]) > 100.0);  // the integral kept growing (no anti-windup: documented)
}

TEST_CASE("stability: one integrator is accepted; others are refused naming the key, unless allowed") {
  CHECK(ErrorOf(Lti({{2.0, 95.0}, {1.0, 0.0}})).empty());
  const std::string rhp = ErrorOf(Lti({{1.0}, {1.0, -5.0}}));
  CHECK(rhp.find("controller.lti.feedback: unstable") != std::string::npos);
  CHECK(rhp.find("allow_unstable") != std::string::npos);
  CHECK(rhp.find("s = 5") != std::string::npos);  // the pole in s, as the user wrote it
  CHECK(ErrorOf(Lti({{1.0}, {1.0, 0.0, 0.0}})).find("2 integrator(s)") != std::string::npos);
  CHECK(ErrorOf(Lti({{1.0}, {1.0, 0.0, 100.0}})).find("unstable") != std::string::npos);  // undamped oscillator
  CHECK(ErrorOf(Lti({}, {{1.0}, {1.0, -1.0}})).find("controller.lti.reference: unstable") != std::string::npos);
  ctl::LtiConfig allowed = Lti({{1.0}, {1.0, -5.0}});
  allowed.allow_unstable = true;
  CHECK(ErrorOf(allowed).empty());
  ctl::LtiConfig z = Lti({{1.0}, {1.0, -1.5}});
  z.domain = ctl::TfDomain::kZ;
  CHECK(ErrorOf(z).find("z = 1.5") != std::string::npos);
}

TEST_CASE("refusals name the key: improper, empty, non-finite, too many poles, bad limits") {
  CHECK(ErrorOf(Lti({{1.0, 2.0, 3.0}, {1.0, 4.0}})).find("controller.lti.feedback.num: [1, 2, 3] over [1, 4]: improper") == 0);
  CHECK(ErrorOf(Lti({{1.0}, {}})).find("controller.lti.feedback.den: missing or empty") == 0);
  CHECK(ErrorOf(Lti({{}, {1.0, 2.0}})).find("controller.lti.feedback.num: missing or empty") == 0);
  CHECK(ErrorOf(Lti({{1.0, NAN}, {1.0, 2.0}})).find("controller.lti.feedback.num: [1, nan]: coefficient 2 is not finite") == 0);
  CHECK(ErrorOf(Lti({{1.0}, {0.0, 0.0}})).find("controller.lti.feedback.den: [0, 0]: all zero") == 0);
  CHECK(ErrorOf(Lti({}, {{1.0}, std::vector<double>(18, 1.0)})).find("controller.lti.reference.den: 17 poles") == 0);
  // Leading zeros are dropped before the degree is compared (tfdata pads with them).
  CHECK(ErrorOf(Lti({{0.0, 0.0, 1.0}, {1.0, 4.0}})).empty());
  ctl::LtiConfig bad = Lti({{1.0}, {1.0, 1.0}});
  bad.saturation_mm = -1.0;
  CHECK(ErrorOf(bad).find("controller.lti.saturation_mm") == 0);
}

TEST_CASE("Linearize: G_yr = C T G / (1 + C G) on a plant, as the design analysis computes it") {
  const ctl::LtiDesign d = ctl::MakeLtiDesign(
      Lti({{2.0, 95.0}, {1.0, 0.0}}, {{50.83163360273612, 8570.397339444286}, {1.0, 8570.397339444286}}), kDt);
  const ctl::LtiController c(d);
  const ctl::ControllerLti lin = c.Linearize(0.0);
  const ctl::DiscreteSs g = ctl::ServoZoh(rths::models::ServoPreset("avg"), kDt);
  for (double f : {0.5, 3.0, 20.0, 100.0}) {
    CAPTURE(f);
    const cd C = d.feedback.discrete.Response(f), T = d.reference.discrete.Response(f), G = g.Response(f);
    const cd expected = C * T * G / (1.0 + C * G);
    CHECK(std::abs(ctl::TrackingResponse(lin, g, f) - expected) < 1e-9 * std::abs(expected));
  }
  const ctl::LoopAnalysis loop = ctl::AnalyzeLoop(lin.fb, g);
  CHECK(loop.stable);
  CHECK(!loop.crossovers.empty());
}

TEST_CASE("Step allocates nothing") {
  ctl::LtiConfig cfg = Lti({{1.0, 30.0, 200.0}, {1.0, 50.0, 900.0, 0.0}}, {{2.0, 10.0}, {1.0, 20.0}});
  cfg.saturation_mm = 10.0;
  cfg.rate_limit_mm_s = 1000.0;
  auto c = ctl::MakeTrackingController([&] {
    ctl::ControllerConfig cc;
    cc.kind = ctl::ControllerKind::kLti;
    cc.lti = cfg;
    return cc;
  }(), kDt);
  double sink = 0.0;
  const long before = rths_test::AllocationCount();
  for (int k = 0; k < 10000; ++k) sink += c->Step({std::sin(1e-3 * k), 0, 0, 0}, {0.5 * std::sin(1e-3 * k), 0, 0}).u_mm;
  CHECK(rths_test::AllocationCount() - before == 0);
  CHECK(std::isfinite(sink));
}

TEST_CASE("scenario keys: [controller.lti] read, written back, and refused with the file and key") {
  const std::string base = R"(
[run]
dt_s = 0.000244140625
duration_s = 1.0
[controller]
kind = "lti"
[controller.lti]
feedback = { num = [2, 95], den = [1, 0] }
reference = { num = [50.83163360273612, 8570.397339444286], den = [1, 8570.397339444286] }
saturation_mm = 20
)";
  const rths::scenario::Scenario s = rths::scenario::ParseScenario(base, "x.toml");
  CHECK(s.controller.kind == ctl::ControllerKind::kLti);
  CHECK(s.controller.lti.feedback.num == std::vector<double>{2.0, 95.0});
  CHECK(s.controller.lti.reference.den == std::vector<double>{1.0, 8570.397339444286});
  CHECK(s.controller.lti.saturation_mm == 20.0);
  CHECK(s.controller.lti.discretisation == ctl::Discretisation::kTustin);
  const rths::scenario::Scenario back = rths::scenario::ParseScenario(rths::scenario::ToToml(s), "y.toml");
  CHECK(back.controller.lti == s.controller.lti);

  auto error_of = [](const std::string& text) { return rths_test::ParseError(text); };
  std::string bad = base;
  bad.replace(bad.find("den = [1, 0]"), 12, "den = [1, -3]");
  CHECK(error_of(bad).find("x.toml: controller.lti.feedback: unstable") == 0);
  bad = base;
  bad.replace(bad.find("num = [2, 95]"), 13, "num = [1, 2, 95]");
  CHECK(error_of(bad).find("x.toml: controller.lti.feedback.num: ") == 0);
  bad = base;
  bad.replace(bad.find("num = [2, 95]"), 13, "num = [2, \"95\"]");
  CHECK(error_of(bad).find("x.toml: controller.lti.feedback.num: element 2 is string") == 0);
  bad = base;
  bad.replace(bad.find("num = [2, 95]"), 13, "nom = [2, 95]");
  CHECK(error_of(bad).find("x.toml: controller.lti.feedback.nom: unknown key") == 0);
  bad = base + "domain = \"w\"\n";
  CHECK(error_of(bad).find("x.toml: controller.lti.domain: \"w\" is not allowed") == 0);
  // A table that is not used (another kind) is still read and written, but its design is not checked.
  std::string other = base;
  other.replace(other.find("kind = \"lti\""), 12, "kind = \"none\"");
  other.replace(other.find("den = [1, 0]"), 12, "den = [1, -3]");
  CHECK(error_of(other).empty());
}

TEST_CASE("examples/matlab/rths_lti_toml.m (GNU Octave) writes [controller] lines that design to the same coefficients") {
  rths_test::RequireTool("octave-cli", "octave");
  const std::string dir = std::string(RTHS_SOURCE_DIR) + "/examples/matlab";
  const std::string out = (std::filesystem::temp_directory_path() / ("rths_lti_toml_" + std::to_string(::getpid()) + ".toml")).string();
  // The benchmark's example, continuous, with every digit of MATLAB's tf object.
  const std::string script = "addpath('" + dir + "'); t = rths_lti_toml([2 95], [1 0], [50.83163360273612 8570.397339444286], "
                             "[1 8570.397339444286]); f = fopen('" + out + "', 'w'); fprintf(f, '%s', t); fclose(f);";
  // octave-cli may print "error: ignoring const execution_exception& while preparing to exit" and exit 0.
  REQUIRE(std::system(("octave-cli --no-gui --norc --eval \"" + script + "\" > /dev/null 2>&1").c_str()) == 0);
  std::ifstream in(out);
  const std::string lines((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(out);
  const rths::scenario::Scenario s =
      rths::scenario::ParseScenario("[run]\ndt_s = 0.000244140625\nduration_s = 1.0\n" + lines, "octave.toml");
  CHECK(s.controller.kind == ctl::ControllerKind::kLti);
  CHECK(s.controller.lti.feedback.num == std::vector<double>{2.0, 95.0});
  CHECK(s.controller.lti.reference.num == std::vector<double>{50.83163360273612, 8570.397339444286});
  CHECK(s.controller.lti.reference.den == std::vector<double>{1.0, 8570.397339444286});
  const ctl::LtiDesign d = ctl::MakeLtiDesign(s.controller.lti, kDt);
  CHECK(d.feedback.discrete.b[0] == 2.0115966796875);
  CHECK(d.reference.discrete.b[0] == doctest::Approx(25.35336272).epsilon(1e-9));
}
