// The table of the paper's reproductions (studies/study_table.h): the one list `rths reproduce`,
// its --help and bench-compare --outputs read; the claims' standing and how a claim is printed.
#include <doctest/doctest.h>

#include <set>
#include <string>

#include "core/error.h"
#include "studies/study_table.h"

namespace st = rths::studies;

TEST_CASE("study table: every study once, each with a reproduction and a standing of its claims") {
  std::set<std::string> names;
  for (const auto& s : st::Studies()) {
    CAPTURE(s.name);
    CHECK(names.insert(s.name).second);
    CHECK(static_cast<bool>(s.reproduce));
    REQUIRE(static_cast<bool>(s.claims));
    for (const char* plant : {"physical", "linear"}) {
      const std::string standing = s.claims(plant);
      CHECK((standing.rfind("required", 0) == 0 || standing.rfind("reported", 0) == 0));
    }
  }
  CHECK(st::StudyNames() == std::vector<std::string>{"fig5", "fig6", "fig7", "fig8", "fig9", "fig11", "table2",
                                                      "benchmark", "marths", "nonlinear"});
  CHECK(&st::StudyNamed("table2") == &st::Studies()[6]);
  CHECK_THROWS_WITH_AS(st::StudyNamed("fig10"), doctest::Contains("one of fig5, fig6"), rths::Error);
}

TEST_CASE("study table: the standing of the claims and a claim as printed") {
  const auto& fig6 = st::StudyNamed("fig6");
  CHECK(st::Standing(fig6, "linear", false) == "required on the linear plant: the test suite asserts it (with --quick)");
  CHECK(st::Standing(fig6, "physical", true) ==
        "reported on the physical plant: docs/experiments.md says which hold there and why; --quick: shorter records, "
        "noisier numbers than the full run");
  // fig5 has no records for --quick to shorten.
  CHECK(st::Standing(st::StudyNamed("fig5"), "physical", true) == "required: the test suite asserts E6 within 2 %");
  const st::Claim c{"E6: the six peak forces within 2 % of the reference", true, "largest peak difference 0.40 %"};
  CHECK(st::ClaimLine(c, "required") ==
        "[holds] E6: the six peak forces within 2 % of the reference\n    largest peak difference 0.40 %\n"
        "    (required)\n");
  const st::Claim no{"x", false, "y"};
  CHECK(st::ClaimLine(no, "reported").rfind("[does not hold] x\n", 0) == 0);
}
