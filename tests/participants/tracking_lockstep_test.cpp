// docs/experiments.md E3 through the whole lockstep system: the tracking scenarios of
// scenarios/ (Eq. 30 plant, ZOH at 2 kHz, predefined BLWN, 60 s) run as a participant group,
// and Eq. 31 on the logged r_k, y_k must meet the same bounds as the offline check.
#include <doctest/doctest.h>

#include <vector>

#include "io/run_log.h"
#include "signal/metrics.h"
#include "run_support.h"
#include "test_support.h"

using namespace rths_test;

namespace {
double TrackingErrorPct(const std::string& scenario_name) {
  const auto s = rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/" +
                                              scenario_name + ".toml");
  const auto dir = TempDir(scenario_name);
  REQUIRE(RunMemq({s}, dir).code == 0);
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  REQUIRE(log.CompleteSteps() == s.steps());
  std::vector<double> r, y;
  for (std::int64_t k = 0; k < s.steps(); ++k) {
    r.push_back(log.desired[k].r_mm);
    y.push_back(log.measured[k].y_mm);
  }
  const double pct = rths::signal::RmsErrorPercent(r, y);
  MESSAGE(scenario_name << ": " << pct << " %");
  return pct;
}
}  // namespace

TEST_CASE("proposed feedforward on its design model, through the lockstep: < 1 % and < 2.5 %") {
  CHECK(TrackingErrorPct("tracking_ff_0-5hz") < 1.0);
  CHECK(TrackingErrorPct("tracking_ff_0-15hz") < 2.5);
}

TEST_CASE("no compensation, through the lockstep: within 2 points of 16.5 % and 46.1 %") {
  CHECK(TrackingErrorPct("tracking_none_0-5hz") == doctest::Approx(16.5).epsilon(2.0 / 16.5));
  CHECK(TrackingErrorPct("tracking_none_0-15hz") == doctest::Approx(46.1).epsilon(2.0 / 46.1));
}
