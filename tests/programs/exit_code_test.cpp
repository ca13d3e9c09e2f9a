// The one exit-code table (core/exit_code.h): every code distinct, the tools' codes in it, and
// every code documented where users read them (README, docs/lockstep.md, `rths --help`).
#include <doctest/doctest.h>

#include <set>
#include <string>

#include "core/exit_code.h"
#include "ident/fit_status.h"
#include "test_support.h"

using rths_test::Slurp;

TEST_CASE("exit codes: one table, every value distinct, every name distinct") {
  std::set<int> codes;
  std::set<std::string> names;
  for (const auto& e : rths::kExitCodeTable) {
    CAPTURE(e.name);
    CHECK(codes.insert(e.code).second);
    CHECK(names.insert(e.name).second);
    CHECK(e.code >= 0);
    CHECK(e.code <= 255);
  }
  CHECK(codes.size() == sizeof(rths::kExitCodeTable) / sizeof(rths::kExitCodeTable[0]));
  // The collisions issue 45 named: a failed damper fit and a truncated log were 3 (= a lockstep
  // failure of rths run); log compare's "differ" and export's internal failure were both 1.
  CHECK(rths::ident::kExitFitFailed == rths::kExitFitFailed);
  CHECK(rths::kExitFitFailed != rths::kExitLockstep);
  CHECK(rths::kExitTruncated != rths::kExitLockstep);
  CHECK(rths::kExitNegative != rths::kExitInternal);
  // 128 + N is a signal; the table's own codes stay below it (130 is 128 + SIGINT).
  for (const auto& e : rths::kExitCodeTable) {
    if (e.code != rths::kExitSignalBase && e.code != rths::kExitInterrupted) CHECK(e.code < rths::kExitSignalBase);
  }
  CHECK(rths::kExitInterrupted == rths::kExitSignalBase + 2);
}

TEST_CASE("exit codes: every code documented in the README table, docs/lockstep.md and rths --help") {
  const std::string readme = Slurp(std::string(RTHS_SOURCE_DIR) + "/README.md");
  const std::string lockstep = Slurp(std::string(RTHS_SOURCE_DIR) + "/docs/lockstep.md");
  const std::string help = Slurp(std::string(RTHS_SOURCE_DIR) + "/rths");
  REQUIRE(!readme.empty());
  REQUIRE(!lockstep.empty());
  REQUIRE(!help.empty());
  for (const auto& e : rths::kExitCodeTable) {
    CAPTURE(e.name);
    const std::string row = e.code == rths::kExitSignalBase ? "| 128+N |" : "| " + std::to_string(e.code) + " |";
    CHECK(readme.find(row) != std::string::npos);
  }
  CHECK(lockstep.find("`lib/core/exit_code.h`") != std::string::npos);
  CHECK(lockstep.find("12 `rths log` and `rths export`: a\nlog is truncated") != std::string::npos);
  CHECK(lockstep.find("13 `rths identify --damper`: the fit failed") != std::string::npos);
  CHECK(help.find("12 a truncated log (log,\nexport); 13 a failed damper fit (identify)") != std::string::npos);
}
