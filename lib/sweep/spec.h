#pragma once
/// @file A sweep's SPEC (`rths sweep SPEC.toml`, issue 28): which runs a study of the user's own
/// makes, and how run i's scenario follows from the SPEC and i alone, so that any run can be
/// re-made by itself, bit for bit, on a laptop or on any node of a cluster.
///
///     [sweep]
///     name = "lqg_noise"              # label of the sweep's output folder
///     base = "../default.toml"        # the scenario every run starts from (relative to the SPEC),
///                                     # or, instead of base, [cases] files (one or the other)
///     seed = 1                        # the sweep's seed: every draw derives from it and the run index
///     draws = 100                     # runs per grid point with fresh [draw] values (0: no [draw])
///     record = ["tracking_nrmse_pct", "peak_force_kN", "benchmark_criteria.J2_pct"]  # summary.json fields
///     # [cases]
///     # files = ["case1.toml", "case2.toml"]  # whole scenarios, each a case, in place of `base`
///     [set]                                    # optional: these --set values in every run
///     "run.duration_s" = 10.0
///     [grid]                                   # every combination of these --set values
///     "controller.kind" = ["ff", "ff_lqg"]
///     "controller.lqg.q" = [1e2, 1e3, 1e4]
///     "controller.lti.feedback.den" = [[1, 0], [1, 1]]   # levels may be arrays of numbers
///     [draw]                                   # drawn anew for each run
///     "structure.damping_ratio" = { dist = "normal", mean = 0.02, std = 0.002 }
///     "controller.lti.feedback.num[0]" = { dist = "normal", mean = 2.0, std = 0.2 }  # one element
///     "plant.noise_seed" = { dist = "seed" }
///     [slurm]                                  # optional: for --executor slurm (lib/sweep/slurm.h)
///     partition = "normal"
///     time = "00:30:00"                        # per array task
///     runs_per_task = 25
///     setup = ["module load gcc/12"]           # shell lines the job script runs before rths
///
/// Run order (index 0 .. runs()-1): case (slowest), then the grid's combinations (keys in sorted
/// order, the first key slowest), then the draw (fastest). Run i's values are `--set KEY=VALUE`
/// overrides of its case's file (scenario::LoadScenario(path, sets)); each drawn key has a random
/// stream of its own, seeded from (seed, i, key) by SplitMix64, with normal deviates by the
/// Box-Muller transform written here (std::normal_distribution differs between libraries): the
/// same SPEC and index give the same scenario on every machine, whatever else the sweep holds.
/// A drawn KEY[i] is one element of an array-valued key (sweep/element_keys.h).
#include <cstdint>
#include <string>
#include <vector>

namespace rths::sweep {

/// A distribution of a [draw] key.
struct Draw {
  /// dotted scenario key, e.g. "structure.damping_ratio", or one element of an array-valued key,
  /// "controller.lti.feedback.num[0]" (0-based; sweep/element_keys.h)
  std::string key;
  /// "normal" (mean, std), "uniform" (lo, hi), "lognormal" (mu, sigma of log), "seed" (an integer in
  /// [1, 2^31 - 2]), or the named draw "benchmark_plant" (key "plant.benchmark": the RTHS benchmark's
  /// perturbed plant, models::PerturbedBenchmarkParams about the nominal constants, b1, b2, a3 and
  /// k_e_N_per_m set, with structure.subtract_specimen = true so that the numerical substructure is
  /// the reference minus the perturbed specimen, as the benchmark's reference code runs it)
  std::string dist;
  double a = 0, b = 0;  ///< the parameters, in that order
};

/// One [grid] axis: a key and its values as TOML literals ("\"ff\"", "1000.0", "true", or an
/// array of numbers, "[2, 95]": a level's text in the table).
struct Axis {
  std::string key;
  std::vector<std::string> values;
};

/// `[slurm]`: how `rths sweep --executor slurm` submits the sweep (lib/sweep/slurm.h); flags of
/// the same names override it. Empty strings leave sbatch's (the cluster's) defaults.
struct SlurmSettings {
  std::string partition;              ///< sbatch --partition
  std::string time;                   ///< sbatch --time per array task, e.g. "00:30:00"
  std::string account;                ///< sbatch --account
  std::int64_t runs_per_task = 0;     ///< runs per array task (0: 25, raised to keep <= 1000 tasks)
  int cpus_per_task = 1;              ///< sbatch --cpus-per-task; each task runs that many runs at a time
  int retries = 1;                    ///< times a task whose runs left no row is submitted again
  std::vector<std::string> sbatch_args;  ///< more sbatch options, e.g. ["--qos=short", "--mem=2G"]
  /// Shell lines the job script runs, in order, before the rths command, e.g. ["module load
  /// gcc/12"] (each single-quoted and eval'd: a line that fails stops the task; SetupLineProblem)
  std::vector<std::string> setup;
};

/// Why `line` cannot be a [slurm] setup line ("" if it can): empty or blank, or holding a control
/// character such as a newline (one entry is one line of the script), or longer than 4096 bytes.
std::string SetupLineProblem(const std::string& line);

/// A parsed, validated SPEC (paths absolute).
struct Spec {
  std::string path;                 ///< the SPEC file
  std::string name = "sweep";
  std::vector<std::string> cases;   ///< scenario files: [cases] files, or the one `base`
  std::uint64_t seed = 1;
  std::int64_t draws = 0;           ///< runs per grid point (0: one, without draws)
  std::vector<std::string> record;  ///< summary.json fields recorded per run
  /// [set]: KEY = VALUE for every run (TOML literals, sorted by key), applied before the grid's
  /// and the draws' values; not a column of the table (the same in every row).
  std::vector<std::pair<std::string, std::string>> fixed;
  std::vector<Axis> grid;           ///< sorted by key
  std::vector<Draw> draw;           ///< sorted by key
  SlurmSettings slurm;              ///< [slurm]

  /// Grid combinations (1 without a grid).
  std::int64_t combinations() const;
  /// Runs of the sweep: cases x combinations x max(draws, 1).
  std::int64_t runs() const;
};

/// One run of a sweep, as the SPEC and its index define it.
struct RunPoint {
  std::int64_t index = 0;
  std::int64_t case_index = 0, combination = 0, draw = 0;
  std::string scenario;             ///< the case's file
  /// "KEY=VALUE": [set] values, grid values, then drawn values (key order); a drawn element is
  /// "KEY[i]=VALUE", which ScenarioSets (sweep/element_keys.h) turns into the whole array
  std::vector<std::string> sets;
};

/// The largest sweep accepted (runs()).
inline constexpr std::int64_t kMaxRuns = 10'000'000;

/// Parses and validates SPEC text (`path` names it in errors and anchors relative paths). Throws
/// rths::Error naming the file, the key and the allowed values.
Spec ParseSpec(const std::string& text, const std::string& path);
/// Reads and parses a SPEC file, and checks its drawn elements against its cases
/// (CheckElementKeys); throws rths::Error (unreadable file, as ParseSpec).
Spec LoadSpec(const std::string& path);
/// The scenario keys a draw sets, the table's columns for it: its key, or for "benchmark_plant"
/// plant.benchmark.b1, .b2, .a3 and .k_e_N_per_m.
std::vector<std::string> DrawColumns(const Draw& d);

/// Run `index` (0 <= index < spec.runs(); throws rths::Error otherwise).
RunPoint PointOf(const Spec& spec, std::int64_t index);

/// A double as a TOML float literal: the shortest text that reads back as the same double, bit
/// for bit ("1.0", not "1").
std::string FloatLiteral(double x);

/// SplitMix64 (Steele, Lea and Flood 2014): the next value of the sequence after `state`,
/// advancing it. A seed mixer with good avalanche, used to derive each run's streams.
std::uint64_t SplitMix64(std::uint64_t* state);

}  // namespace rths::sweep
