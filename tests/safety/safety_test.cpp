// The safety monitor (docs/safety.md): every trigger on synthetic signals, and through the
// lockstep with an injected divergence (a sign error in the controller's output, which turns the
// damper into negative damping): the run stops cleanly, named, with the log intact.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "io/run_log.h"
#include "safety/monitor.h"
#include "signal/blwn.h"
#include "run_support.h"
#include "test_support.h"

using namespace rths_test;
using rths::safety::Monitor;

namespace {
constexpr double kDt = 0.0005;

std::string FirstTrip(Monitor& m, int n, auto&& signal) {
  for (int k = 0; k < n; ++k) {
    double r, u, y, f;
    signal(k, &r, &u, &y, &f);
    if (auto why = m.Check(k, r, u, y, f); !why.empty()) return std::string(why);
  }
  return "";
}
}  // namespace

TEST_CASE("each limit trips on its own, naming the signal, the value and the key") {
  rths::safety::SafetyConfig cfg;
  {
    Monitor m(cfg, kDt);
    CHECK(m.Check(0, 1.0, 1.0, 1.0, 1.0).empty());
    const std::string why(m.Check(1, 160.0, 1.0, 1.0, 1.0));
    CHECK(why.find("step 1") != std::string::npos);
    CHECK(why.find("|r| = 160.00 mm exceeds the stroke 152.4 mm (safety.stroke_mm)") != std::string::npos);
  }
  {
    Monitor m(cfg, kDt);
    CHECK(std::string(m.Check(0, 1.0, -153.0, 1.0, 1.0)).find("actuator command |u|") != std::string::npos);
  }
  {
    Monitor m(cfg, kDt);
    CHECK(std::string(m.Check(0, 150.0, 150.0, 152.5, 1.0)).find("measured displacement |y|") != std::string::npos);
  }
  {
    Monitor m(cfg, kDt);
    CHECK(std::string(m.Check(0, 1.0, 1.0, 1.0, -600.0)).find("|f| = 600.0 kN exceeds the actuator's 556 kN") !=
          std::string::npos);
  }
  {
    Monitor m(cfg, kDt);
    CHECK(std::string(m.Check(0, 30.0, 30.0, 1.0, 1.0)).find("tracking error |r - y| = 29.00 mm") != std::string::npos);
  }
  {
    Monitor m(cfg, kDt);
    CHECK(std::string(m.Check(0, std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0, 1.0)).find("not finite") !=
          std::string::npos);
  }
  {
    cfg.enabled = false;
    Monitor m(cfg, kDt);
    CHECK(m.Check(0, 1e9, 1e9, 1e9, 1e9).empty());
  }
}

TEST_CASE("several actuators: every limit is checked on each actuator, and the reason names it") {
  rths::safety::SafetyConfig cfg;
  const double r[2] = {1.0, 1.0}, u[2] = {1.0, 1.0};
  {
    Monitor m(cfg, kDt, 2);
    const double y[2] = {1.0, 1.0};
    CHECK(m.CheckActuators(0, r, u, y, 0.0).empty());
    const double y2[2] = {1.0, 160.0};  // only the second actuator leaves its stroke
    const std::string why(m.CheckActuators(1, r, u, y2, 0.0));
    CHECK(why.find("step 1") != std::string::npos);
    CHECK(why.find("actuator 2: measured displacement |y| = 160.00 mm") != std::string::npos);
  }
  {
    Monitor m(cfg, kDt, 2);
    const double y[2] = {1.0, -29.0};
    CHECK(std::string(m.CheckActuators(0, r, u, y, 0.0)).find("actuator 2: tracking error |r - y| = 30.00 mm") !=
          std::string::npos);
  }
  {
    Monitor m(cfg, kDt, 2);
    const double y[2] = {std::numeric_limits<double>::infinity(), 1.0};
    CHECK(std::string(m.CheckActuators(0, r, u, y, 0.0)).find("actuator 1: a signal is not finite") !=
          std::string::npos);
    const double y_ok[2] = {1.0, 1.0};
    const std::string force(m.CheckActuators(1, r, u, y_ok, 600.0));  // the force is no actuator's
    CHECK(force.find("|f| = 600.0 kN") != std::string::npos);
    CHECK(force.find("actuator") == force.find("actuator's"));
  }
  {
    // Divergence on the second actuator only: each actuator keeps its own windows.
    Monitor m(cfg, kDt, 2);
    std::string why;
    for (int k = 0; k < 40000 && why.empty(); ++k) {
      const double t = k * kDt;
      const double y[2] = {1.0 - 0.3 * std::sin(2 * M_PI * 20.0 * t),
                           1.0 - 0.1 * std::exp(3.0 * t) * std::sin(2 * M_PI * 20.0 * t)};
      why = m.CheckActuators(k, r, u, y, 0.0);
    }
    CHECK(why.find("actuator 2: tracking error diverging") != std::string::npos);
  }
  CHECK_THROWS_AS(Monitor(cfg, kDt, 0), rths::Error);
  // One actuator: the reasons read as they always did, without an actuator's number.
  Monitor one(cfg, kDt);
  CHECK(std::string(one.Check(0, 1.0, 1.0, 160.0, 0.0)).find("actuator 1") == std::string::npos);
}

TEST_CASE("divergence trips on exponential growth long before the hard limits") {
  rths::safety::SafetyConfig cfg;
  Monitor m(cfg, kDt);
  // Tracking error e = 0.1 mm * exp(3 t) sin(2 pi 20 t): the hard limits are far away when it trips.
  const std::string why = FirstTrip(m, 40000, [](int k, double* r, double* u, double* y, double* f) {
    const double t = k * kDt;
    *r = 1.0;
    *u = 1.0;
    *y = 1.0 - 0.1 * std::exp(3.0 * t) * std::sin(2 * M_PI * 20.0 * t);
    *f = 0.0;
  });
  REQUIRE(!why.empty());
  CHECK(why.find("diverging") != std::string::npos);
  // It fired while the error was still below the 25 mm limit.
  const auto pos = why.find("to ");
  REQUIRE(pos != std::string::npos);
  CHECK(std::stod(why.substr(pos + 3)) < cfg.max_error_mm);
}

TEST_CASE("a bounded random response, with its start-up, never trips") {
  rths::safety::SafetyConfig cfg;
  Monitor m(cfg, kDt);
  const int n = 120000;  // 60 s
  const auto r = rths::signal::Blwn(15.0, 20.0, kDt, n, 3, 2.0);
  const auto e = rths::signal::Blwn(30.0, 2.0, kDt, n, 4, 0.0);  // starts from rest, ramps up
  const std::string why = FirstTrip(m, n, [&](int k, double* rr, double* u, double* y, double* f) {
    *rr = r[k];
    *u = r[k];
    *y = r[k] - e[k];
    *f = 2.0 * r[k];
  });
  CHECK(why.empty());
}

namespace {
/// A short run of a light SDOF (10 t, 5 Hz) with the damper at 0 A and the controller's output
/// sign flipped: the damper's viscous force now pushes along the motion, a negative damping of
/// about c0 / (2 m) = 4 1/s: exponential growth.
MemqRun RunDivergent(const fs::path& dir, const std::string& safety) {
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 10.0
[structure]
mass_kg = 10000.0
[structure.ground]
rms_mm_s2 = 1500.0
[semiactive]
mode = "passive_off"
[lockstep]
rerequest_ms = 200.0
[safety]
)" + safety).string());
  rths::lockstep::Faults f;
  f.command_gain = -1.0;
  return RunMemq({s}, dir, "controller", f);
}

void CheckStopped(const fs::path& dir, const MemqRun& r, const std::string& reason_part) {
  CHECK(r.code == rths::kExitSafety);
  const std::string& why = r.errors.back();  // the integrator (clock) is last
  CAPTURE(why);
  CHECK(why.rfind("safety: step ", 0) == 0);
  CHECK(why.find(reason_part) != std::string::npos);
  const auto k = std::stoll(why.substr(13));
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  CHECK(log.CompleteSteps() == k + 1);  // everything up to the step that tripped is logged
  CHECK(log.AbortReason().find(reason_part) != std::string::npos);
  for (std::int64_t j = 0; j <= k; ++j) CHECK(std::isfinite(log.measured[j].y_mm));
}
}  // namespace

TEST_CASE("through the lockstep: an unstable loop is stopped by each trigger, log intact") {
  SUBCASE("divergence") {
    const auto dir = TempDir("safety_growth");
    CheckStopped(dir, RunDivergent(dir, "stroke_mm = 10000.0\nforce_kN = 1e6\nmax_error_mm = 10000.0\n"),
                 "diverging");
  }
  SUBCASE("tracking error") {
    const auto dir = TempDir("safety_error");
    CheckStopped(dir, RunDivergent(dir, "max_error_mm = 5.0\n"), "tracking error |r - y|");
  }
  SUBCASE("stroke") {
    const auto dir = TempDir("safety_stroke");
    CheckStopped(dir, RunDivergent(dir, "stroke_mm = 3.0\nmax_error_mm = 1000.0\nenabled = true\n"),
                 "exceeds the stroke 3 mm");
  }
  SUBCASE("force") {
    const auto dir = TempDir("safety_force");
    CheckStopped(dir, RunDivergent(dir, "force_kN = 150.0\nmax_error_mm = 1000.0\n"), "exceeds the actuator's 150 kN");
  }
}
