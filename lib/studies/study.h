#pragma once
/// @file What every reproduction of the paper (docs/experiments.md) shares: its options, the output
/// folder rule, the plant check, and the skeleton every lockstep study follows:
///
///     specs   a function builds the study's RunSpecs (one scenario per run, built in code);
///     batch   RunStudyBatch: the `--set` overrides, Preflight, then the runs `jobs` at a time with
///             progress (studies/batch.h);
///     table   a function turns the RunResults (and the runs' logs) into the study's rows;
///     outputs a function writes its files into opts.out_dir.
///
/// tools/reproduce.cpp (`rths reproduce NAME`) parses options and runs the study of the table in
/// studies/study_table.h, which calls the studies' Reproduce* (studies/fig5.h ...
/// studies/nonlinear_delay.h) and says what to print; tests call them directly. Every result
/// carries its claims (`claims`). Every Reproduce* writes into
/// opts.out_dir (created; refused if it exists and is not empty): CSV tables (RFC 4180, io/csv.h),
/// Markdown where there is a table, PNG figures made with gnuplot (io/plot.h) and, for lockstep
/// studies, every run's folder under out_dir/runs/.
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller_config.h"
#include "core/progress.h"
#include "studies/batch.h"

namespace rths::studies {

struct ReproduceOptions {
  std::filesystem::path out_dir;          ///< where the files go
  bool quick = false;                     ///< shorter records (tests); full: docs/experiments.md lengths
  std::string plant = "physical";         ///< "physical" (docs/models.md section 5) | "linear" (Eqs. 28-30)
  int jobs = 2;                           ///< lockstep groups run at the same time (threads)
  std::function<void(std::string_view)> log;  ///< progress lines ("" = silent)
  std::string gnuplot = "gnuplot";        ///< plotting program
  /// The rths checkout the user named (the tool's RTHS_SOURCE_DIR): searched first for the studies'
  /// base scenarios (scenarios/fig9_base.toml, ...); "" only the search of io::FindSourceFile.
  std::filesystem::path source_dir;
  /// `--set KEY=VALUE` overrides applied to every lockstep run's scenario after the study set its
  /// own keys (scenario::WithOverrides, in Preflight); checked like a file.
  std::vector<std::string> overrides;
  /// Progress with an ETA of the lockstep batches (null: none); the main program decides.
  ProgressLine* progress = nullptr;
  /// table2 only: also run the extended table (table2_extended.csv/.md/.png): the field's adaptive
  /// compensators and a PI + phase lead beside the paper's proposed controllers. The paper's 36
  /// rows and their files are the same with or without it.
  bool extended = false;
  /// benchmark only: keep every perturbed run's log.lcm (default: removed once scored).
  bool keep_logs = false;
  /// Where the lockstep runs are made: empty, here, `jobs` at a time (RunBatch); else this
  /// function makes them (e.g. as a Slurm job array, sweep/study_on_slurm.h) and returns their
  /// results in spec order, calling `progress` after each as RunBatch does.
  std::function<std::vector<RunResult>(const std::vector<RunSpec>&, const Progress&)> run_batch;
  /// Ctrl-C and --resume of the runs made here (BatchControl; with resume, out_dir may hold the
  /// interrupted study).
  BatchControl batch;
};

/// One of the paper's claims (docs/experiments.md) checked on our numbers.
struct Claim {
  std::string text;
  bool holds = false;
  std::string detail;              ///< the numbers behind it
};

/// A claim as a line of a reproduction's Markdown: "- **Holds:** TEXT.  \n  DETAIL\n" (or "Does not
/// hold:"), as `rths reproduce` prints it "[holds]" / "[does not hold]".
std::string ClaimMarkdown(const Claim& c);

/// Now, as "YYYY-MM-DD HH:MM UTC": the stamp of a reproduction's Markdown.
std::string UtcStamp();

/// Seconds since t0 on the steady clock: a study's wall time.
double SecondsSince(std::chrono::steady_clock::time_point t0);

/// Creates `dir`, or accepts it if it exists and is empty; throws rths::Error if it holds
/// anything (a reproduction never overwrites an earlier one), unless `resume` (it holds the
/// interrupted study being finished).
void PrepareOutDir(const std::filesystem::path& dir, bool resume = false);

/// Throws rths::Error with a clear message unless `plant` is "linear" or "physical", and, for
/// "physical", unless this build's plant really runs the physics-based actuator (it runs a
/// 0.1 s probe on both plants in a scratch folder under `scratch_parent` and compares).
void RequirePlant(const std::string& plant, const std::filesystem::path& scratch_parent);

/// The skeleton's batch step: applies opts.overrides and Preflight to `specs` (studies/batch.h),
/// says `intro` through opts.log (if set), then runs them opts.jobs at a time with opts.progress
/// and `on_run` after each run. Returns the results in spec order; a failed run is in its result.
std::vector<RunResult> RunStudyBatch(std::vector<RunSpec>* specs, const ReproduceOptions& opts,
                                     const std::string& intro, const Progress& on_run = {});

/// The "stopped" field of a study: "no" for a run that ran to the end, else the reason (the
/// safety monitor's message, or the failure) on one line.
std::string StoppedText(const RunResult& r);

/// Controller settings of a Table 1 row: the kind alone; with the delay it compensates (poly3,
/// lead) [ms]; or with its design model (a preset: "0.0A", "2.5A", "avg").
control::ControllerConfig ControllerKind(const std::string& kind);
control::ControllerConfig ControllerDelay(const std::string& kind, double delay_ms);
control::ControllerConfig ControllerModel(const std::string& kind, const std::string& preset);

}  // namespace rths::studies
