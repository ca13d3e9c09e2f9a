// bench-diagnosis [--seeds N] [--first-seed S] [--duration S] [--blocks | --independent] [--noise-y MM] [--noise-f KN] [--verbose] [--write-records DIR] [--no-pairs] [--only KIND ...] [--runtime-only]
// The diagnosis's validation harness (lib/validation/harness.h, docs/diagnosis.md "Harness"):
// records with known effects, diagnosed without the truth; prints one line per case, the
// confusion table (true effect vs verdict), the held-out shrink per effect and the scores against
// harness targets (docs/diagnosis.md); then the runtime of one diagnosis on a 60 s / 2 kHz training and test record.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "io/source_tree.h"
#include "validation/harness.h"

int main(int argc, char** argv) {
  CLI::App app{"bench-diagnosis: confusion table and held-out shrink of rths diagnose"};
  rths::validation::HarnessOptions o;
  bool no_pairs = false, runtime_only = false;
  app.add_option("--seeds", o.seeds, "seeds per case kind (default 5)");
  app.add_option("--duration", o.duration_s, "record length [s] (default 20)");
  bool blocks = false, independent = false;
  app.add_option("--first-seed", o.first_seed, "first seed (default 1): seeds first .. first + N - 1");
  app.add_flag("--blocks", blocks, "make the records with the effect blocks (validation::MakeRecordBlocks) instead of the "
                                   "plant's rig mode (models::MakeRig, the default)");
  app.add_flag("--independent", independent,
               "make the records with the independently written generator (validation::MakeIndependentRecord: "
               "continuous RK4, its own effect forms, excitation families and anti-aliased noise)")
      ->excludes("--blocks");
  app.add_flag("--no-pairs", no_pairs, "leave out the two-effect cases");
  app.add_option("--only", o.only, "case kinds to run");
  app.add_option("--noise-y", o.noise_y_mm, "sensor noise rms on y [mm] (default 0.01)");
  app.add_option("--noise-f", o.noise_f_kN, "sensor noise rms on f [kN] (default 0.2)");
  app.add_flag("--verbose", o.verbose, "print every diagnosis summary");
  app.add_option("--write-records", o.write_dir, "write each case's training and test records to this folder (rig record csv, for rths diagnose)");
  app.add_flag("--runtime-only", runtime_only, "only the 60 s runtime measurement");
  CLI11_PARSE(app, argc, argv);
  o.pairs = !no_pairs;
  o.generator = independent ? rths::validation::Generator::kIndependent
                : blocks      ? rths::validation::Generator::kBlocks
                              : rths::validation::Generator::kRig;
  try {
    if (independent)
      o.ground_g = rths::validation::ReadGroundMotion(rths::io::FindSourceFile("data/ground_motion/elcentro_1940_ns_g.txt"));
    if (!runtime_only) {
      std::printf("harness: %d seeds per case, %.0f s records, generator %s\n", o.seeds, o.duration_s,
                  independent ? "independent (validation::MakeIndependentRecord)"
                  : blocks    ? "effect blocks"
                              : "rig mode (models::MakeRig)");
      const auto cases = rths::validation::RunHarness(o, [](const rths::validation::HarnessCase& c) {
        std::fputs(rths::validation::FormatCase(c).c_str(), stdout);
        std::fflush(stdout);
      });
      const auto sc = rths::validation::ScoreHarness(cases);
      std::printf("\n%s", sc.table.c_str());
    }
    // Runtime on a 60 s / 2 kHz record (train and test 60 s each, pure_delay + damper_scale).
    auto ro = o;
    ro.duration_s = 60.0;
    const auto c = rths::validation::RunHarnessCase("pure_delay+damper_scale", 1, ro);
    std::printf("\nruntime: one diagnosis of a 60 s / 2 kHz training record and a 60 s test record: %.2f s (verdict %s)\n",
                c.runtime_s, fmt::format("{}", fmt::join(c.verdict, ",")).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench-diagnosis: %s\n", e.what());
    return 1;
  }
  return 0;
}
