#pragma once
/// @file The diagnosis's validation harness (docs/diagnosis.md "Validation harness"; bench/diagnosis.cpp and
/// tests/diagnosis/diagnosis_harness_test.cpp): records with known effects, diagnosed without the truth,
/// scored as a confusion table and held-out shrink.
///
/// Each case: a truth (one effect, two effects, none = sensor noise only, or a disturbance
/// outside the library) with parameters drawn from the seed in the ranges of
/// HarnessCaseKinds() (docs/diagnosis.md "Harness"), one training record (BLWN 0-25 Hz command,
/// 4 mm rms, a random current staircase) and one test record (BLWN 0-8 Hz, 5 mm rms, another
/// seed and staircase); sensor noise 0.01 mm and 0.2 kN rms on every record.
/// Right verdict: the set of effects named equals the truth (order free); none -> ["none"];
/// outside the library -> ["unknown"].
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "validation/independent_rig.h"
#include "validation/synthetic.h"

namespace rths::validation {

/// Which generator makes the harness's records.
enum class Generator {
  kRig,          ///< the plant's rig mode (MakeRecordRig)
  kBlocks,       ///< the effect blocks (MakeRecordBlocks)
  kIndependent,  ///< the independently written continuous rig (MakeIndependentRecord), its own
                 ///< effect forms, excitation families and coloured noise (IndependentCaseKinds)
};

struct HarnessOptions {
  int seeds = 5;                 ///< seeds per case kind
  std::uint64_t first_seed = 1;  ///< seeds first_seed .. first_seed + seeds - 1
  double duration_s = 20.0;      ///< each record's length [s]
  Generator generator = Generator::kBlocks;
  std::vector<std::string> only; ///< case kinds to run (empty: all)
  bool pairs = true;             ///< include the two-effect cases
  double noise_y_mm = 0.01, noise_f_kN = 0.2;
  bool verbose = false;          ///< print each diagnosis's Summary() to stdout
  /// Non-empty: each case's training and test records are written there as rig records
  /// (<kind>-s<seed>-train.csv, -test.csv; io::WriteRigRecord), for `rths diagnose` to rerun.
  std::string write_dir;
  /// kIndependent: the ground acceleration [g] of the earthquake test commands (ReadGroundMotion;
  /// the caller reads the file, data/ground_motion/elcentro_1940_ns_g.txt).
  std::vector<double> ground_g;
};

struct HarnessCase {
  std::string kind;                    ///< e.g. "pure_delay", "pure_delay+damper_scale", "none", "unknown_ripple"
  std::vector<std::string> truth;      ///< expected verdict, sorted (["none"] / ["unknown"] for those)
  std::string params;                  ///< the true parameters, as text
  std::uint64_t seed = 0;
  std::vector<std::string> verdict;    ///< the diagnosis's verdict, as returned
  bool right = false;
  double shrink_pct = 0;               ///< held-out shrink of the verdict's channel(s) (mean over the truth's channels)
  /// The verdict names an effect as unconfirmed (the test records do not exercise it): no held-out
  /// shrink to show, so the case is left out of the shrink means.
  bool unconfirmed = false;
  /// The verdict names an effect as drifting over the records (EffectResult::drift).
  bool drift = false;
  double runtime_s = 0;
};

/// The case kinds of the rig and blocks generators: the 12 single effects (every diagnosable entry
/// of models::kEffects), pairs, "none",
/// "unknown_ripple", "unknown_stiffness".
std::vector<std::string> HarnessCaseKinds(bool pairs);

/// The case kinds of the independent generator: the 12 single effects (its own forms), two
/// variants of servovalve_saturation ("@loop": inside the servo loop; "@unreached": a test too slow
/// to reach the limit; the truth of kind@variant is the kind), pairs
/// (load_coupling+gain_error, backlash+oil_column_resonance, pure_delay+damper_scale,
/// gain_error+current_lag, oil_column_resonance+coulomb_friction, servovalve_saturation+current_lag,
/// presliding_friction+damper_scale, command_dead_band+oil_column_resonance,
/// pure_delay+presliding_friction, oil_column_resonance+supply_ripple),
/// "none" (anti-aliased noise with drift), "none_white" (white noise, no drift), "none_drift" (a
/// random-walk sensor drift of 0.5-1.5 x the noise rms on both channels), and outside the
/// library "unknown_ripple" (amplitude-modulated, 11-17 Hz), "unknown_cubic" (F += k3 y^3),
/// "unknown_asymmetric" (valve gain 1 +- a).
std::vector<std::string> IndependentCaseKinds(bool pairs);

/// The case kinds of a generator.
std::vector<std::string> CaseKinds(Generator g, bool pairs);

/// One independent case's truth (parameters drawn from the seed; ranges in docs/diagnosis.md)
/// and its training and test excitations (families drawn from the seed, the test's always another
/// family than the training's). Throws rths::Error for an unknown kind.
struct IndependentCase {
  IndependentTruth truth;       ///< the training record's
  IndependentTruth truth_test;  ///< the test record's (the same but for a damper that goes on heating)
  IndependentExcitation train, test;
  std::string text;  ///< parameters and excitations, as text
};
IndependentCase IndependentHarnessCase(const std::string& kind, std::uint64_t seed, double duration_s,
                                       double noise_y_mm, double noise_f_kN);

/// Draws the truth of a case kind for a seed (parameters in documented ranges).
Truth HarnessTruth(const std::string& kind, std::uint64_t seed, double noise_y_mm, double noise_f_kN,
                   std::string* params_text);

/// Runs one case. progress (may be empty) is called after it.
HarnessCase RunHarnessCase(const std::string& kind, std::uint64_t seed, const HarnessOptions& o);

/// One line per case: kind, seed, RIGHT/wrong, verdict, held-out shrink, runtime, true parameters.
std::string FormatCase(const HarnessCase& c);

/// Runs every case of o (CaseKinds(o.generator, o.pairs), seeds first_seed ..); calls progress after each.
std::vector<HarnessCase> RunHarness(const HarnessOptions& o, const std::function<void(const HarnessCase&)>& progress = {});

/// Scores: fractions right per class and the mean held-out shrink of correctly identified singles.
struct HarnessScore {
  int single_n = 0, single_right = 0;
  int pair_n = 0, pair_right = 0;
  int none_n = 0, none_right = 0, none_as_effect = 0;
  /// unknown_as_effect: named a library effect as if constant (not a drifting one, which is right).
  int unknown_n = 0, unknown_right = 0, unknown_as_effect = 0;
  double single_shrink_mean = 0;   ///< over correctly identified single-effect cases
  std::string table;               ///< confusion table and shrink per effect, as text
};
HarnessScore ScoreHarness(const std::vector<HarnessCase>& cases);

}  // namespace rths::validation
