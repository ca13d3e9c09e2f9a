#pragma once
// Shared by the diagnosis harness tests: run a harness, show every case and the table, and
// check the targets of docs/diagnosis.md "Validation harness" that every generator must meet.
#include <string>

#include <doctest/doctest.h>

#include "validation/harness.h"

namespace rths_test {

/// Runs the harness of o, prints each case's line and the confusion table, returns the score.
inline rths::validation::HarnessScore RunHarnessReported(const rths::validation::HarnessOptions& o) {
  std::string lines;
  const auto cases = rths::validation::RunHarness(o, [&](const rths::validation::HarnessCase& c) {
    lines += rths::validation::FormatCase(c);
  });
  const auto sc = rths::validation::ScoreHarness(cases);
  const std::string report = lines + sc.table;
  MESSAGE(report);
  return sc;
}

/// >= 90 % of the singles and >= 75 % of the pairs right, mean held-out shrink >= 70 %.
inline void CheckHarnessTargets(const rths::validation::HarnessScore& sc) {
  CHECK(sc.single_right >= 0.9 * sc.single_n);
  CHECK(sc.pair_right >= 0.75 * sc.pair_n);
  CHECK(sc.single_shrink_mean >= 70.0);
}

}  // namespace rths_test
