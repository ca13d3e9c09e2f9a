#pragma once
// Shared by the diagnosis harness tests: run a harness, show every case and the table, and
// check the targets of docs/diagnosis.md "Validation harness" that every generator must meet.
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "validation/harness.h"

namespace rths_test {

/// Runs the harnesses of os (one after the other, their cases scored together), prints each case's
/// line and the confusion table, returns the score.
inline rths::validation::HarnessScore RunHarnessReported(const std::vector<rths::validation::HarnessOptions>& os) {
  std::string lines;
  std::vector<rths::validation::HarnessCase> cases;
  for (const auto& o : os) {
    const auto run = rths::validation::RunHarness(o, [&](const rths::validation::HarnessCase& c) {
      lines += rths::validation::FormatCase(c);
    });
    cases.insert(cases.end(), run.begin(), run.end());
  }
  const auto sc = rths::validation::ScoreHarness(cases);
  const std::string report = lines + sc.table;
  MESSAGE(report);
  return sc;
}
inline rths::validation::HarnessScore RunHarnessReported(const rths::validation::HarnessOptions& o) {
  return RunHarnessReported(std::vector<rths::validation::HarnessOptions>{o});
}

/// The case kinds added for issue 42 (the driver's start, the drifting damper, short presliding, the
/// in-loop flow limit, the DAQ's effects) among `kinds`.
inline std::vector<std::string> Issue42Kinds(const std::vector<std::string>& kinds) {
  std::vector<std::string> out;
  for (const auto& k : kinds)
    for (const char* mark : {"current_on", "heating", "@short", "@loop", "channel_skew", "load_cell_inertia"})
      if (k.find(mark) != std::string::npos) {
        out.push_back(k);
        break;
      }
  return out;
}

/// >= 90 % of the singles and >= 75 % of the pairs right, mean held-out shrink >= 70 %.
inline void CheckHarnessTargets(const rths::validation::HarnessScore& sc) {
  CHECK(sc.single_right >= 0.9 * sc.single_n);
  CHECK(sc.pair_right >= 0.75 * sc.pair_n);
  CHECK(sc.single_shrink_mean >= 70.0);
}

}  // namespace rths_test
