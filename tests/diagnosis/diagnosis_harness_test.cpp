// The diagnosis's validation harness, CI size (lib/validation/harness.h; the full one is
// bench/diagnosis.cpp): records with known effects made by the plant's RIG MODE
// (models::MakeRig with plant.effects / plant.unmodelled) and, one seed, by the effect BLOCKS
// (MakeRecordBlocks, the kinds of issue 42 only), diagnosed without the truth, scored against the harness targets
// (docs/diagnosis.md "Validation harness"). Fewer and shorter records than the bench (2 seeds,
// 6 s), the same targets on what it runs. The independent generator's harness is
// tests/diagnosis/diagnosis_independent_test.cpp.
#include <cstdio>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "validation/harness.h"
#include "harness_support.h"

using namespace rths::diagnosis;
using namespace rths::validation;

TEST_CASE("harness (rig mode): confusion table and held-out shrink meet the harness targets") {
  HarnessOptions o;
  o.seeds = 2;
  o.duration_s = 6.0;
  o.generator = Generator::kRig;
  o.pairs = true;
  const auto sc = rths_test::RunHarnessReported(o);
  REQUIRE(sc.single_n == 16 * o.seeds);  // the 14 diagnosable effects of models::kEffects, short presliding, in-loop flow limit
  REQUIRE(sc.pair_n > 0);
  REQUIRE(sc.none_n == 2 * o.seeds);     // none, none_current_on
  REQUIRE(sc.unknown_n == 3 * o.seeds);  // ripple, stiffness, heating
  rths_test::CheckHarnessTargets(sc);
  CHECK(sc.none_as_effect == 0);
  CHECK(sc.unknown_as_effect == 0);
}

TEST_CASE("harness (effect blocks, one seed, the kinds of issue 42): confusion table and held-out shrink meet the harness targets") {
  HarnessOptions o;
  o.seeds = 1;
  o.first_seed = 3;
  o.duration_s = 6.0;
  o.generator = Generator::kBlocks;
  o.pairs = true;
  o.only = rths_test::Issue42Kinds(CaseKinds(o.generator, true));
  const auto sc = rths_test::RunHarnessReported(o);
  REQUIRE(sc.single_n == 4);  // channel_skew, load_cell_inertia, short presliding, in-loop flow limit
  REQUIRE(sc.pair_n == 5);  // the four of issue 42 with their partners and short presliding + dead band
  REQUIRE(sc.none_n == 1);
  REQUIRE(sc.unknown_n == 1);
  rths_test::CheckHarnessTargets(sc);
  CHECK(sc.none_right == sc.none_n);
  CHECK(sc.unknown_right == sc.unknown_n);
}
