#pragma once
/// @file Many lockstep runs side by side: each run made by the supervisor (supervisor/run.h), a
/// whole participant group in this process on its own memq:// instance, `jobs` groups at a time in
/// threads. Every run
/// gets a folder of its own with the exact scenario file that ran (scenario.toml, written by
/// scenario::ToToml and loaded back, so its hash is that of the file), log.lcm, signals.csv and
/// summary.json.
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"

namespace rths::studies {

/// One run to make.
struct RunSpec {
  std::string label;                 ///< for progress lines and errors
  scenario::Scenario scenario;       ///< built in code; written to dir/scenario.toml
  std::filesystem::path dir;         ///< the run's folder (created; must not hold a run yet)
};

/// How one run went.
struct RunResult {
  std::string label;
  std::filesystem::path dir;
  bool ok = false;
  std::string error;                 ///< why it failed ("" if ok)
  std::int64_t steps = 0;            ///< complete steps in the log
  double wall_s = 0.0;
  double tracking_pct = 0.0;         ///< Eq. 31 over every logged step (r_k, y_k)
  double peak_force_kN = 0.0;
  /// The benchmark's J1-J9 over the logged steps, for a scenario with a structure.reference_file
  /// (as summary.json's "benchmark_criteria"); why not, in benchmark_error.
  std::optional<signal::BenchmarkCriteria> benchmark;
  std::string benchmark_error;
};

/// Writes spec.scenario into spec.dir/scenario.toml and loads it back (a real file and hash).
scenario::Scenario WriteScenarioFile(const RunSpec& spec);

/// Validates every scenario and builds each of its participants but the logger once
/// (participants::CheckBuildable: the roles of the step table), without running, and throws one rths::Error listing every run that cannot be built (e.g. a
/// controller kind or plant that is not implemented yet) with the component's own message.
void Preflight(const std::vector<RunSpec>& specs);
/// Applies `overrides` (`--set KEY=VALUE`, scenario::WithOverrides) to every spec's scenario,
/// then Preflight, then says through `log` (if set) how much the runs will write. An override
/// that does not check out throws rths::Error naming the --set.
void Preflight(std::vector<RunSpec>* specs, const std::vector<std::string>& overrides,
               const std::function<void(std::string_view)>& log = {});

/// How a batch can be stopped and finished later (`rths reproduce`: Ctrl-C, then --resume).
struct BatchControl {
  /// Set (by a signal handler) to stop: the runs in progress stop at their next step, their
  /// summary.json says "interrupted", no new run starts, and RunBatch throws BatchInterrupted.
  volatile std::sig_atomic_t* interrupted = nullptr;
  /// A run folder whose summary.json says the run ended (any status but "interrupted") is taken as
  /// it is (ResultOfRunFolder); a folder without one, or with an interrupted run, is made again.
  bool resume = false;
};

/// A batch stopped by BatchControl::interrupted: what was done and what was not.
class BatchInterrupted : public Interrupted {
 public:
  BatchInterrupted(std::size_t ended, std::size_t cut, std::size_t not_started)
      : Interrupted("", Describe(ended, cut, not_started)), ended_(ended), cut_(cut), not_started_(not_started) {}
  std::size_t ended() const { return ended_; }              ///< runs that ended (their results stand)
  std::size_t cut() const { return cut_; }                  ///< runs stopped mid-way (summary.json "interrupted")
  std::size_t not_started() const { return not_started_; }  ///< runs never started

 private:
  static std::string Describe(std::size_t ended, std::size_t cut, std::size_t not_started);
  std::size_t ended_, cut_, not_started_;
};

/// Called after each run (from the worker threads, serialised): done so far, total, the result.
using Progress = std::function<void(std::size_t done, std::size_t total, const RunResult&)>;

/// Runs every spec, `jobs` at a time (>= 1), and returns the results in spec order. A failed
/// run is reported in its RunResult (and its summary.json), not thrown.
/// `line`: if not null, shows the batch's progress with an ETA (by simulated steps done).
/// `origin`: the command scenario.toml's header names ("written by rths reproduce; ...").
/// `control`: how it can be interrupted and resumed (BatchControl; throws BatchInterrupted).
std::vector<RunResult> RunBatch(const std::vector<RunSpec>& specs, int jobs, ProgressLine* line = nullptr,
                                const Progress& progress = {}, const std::string& origin = "rths reproduce",
                                const BatchControl& control = {});

/// The RunResult of a run made elsewhere (an array task on a cluster: sweep/study_on_slurm.h),
/// read from its folder's summary.json as RunOne takes it from the supervisor's summary (NaN where
/// the JSON holds null). A folder without a readable summary.json is a failed run saying so.
RunResult ResultOfRunFolder(const std::filesystem::path& dir, const std::string& label);

/// A folder-name-safe form of a label: lower case, runs of other characters -> '-'
/// ("G_FF,0.0A + LP" -> "g_ff-0.0a-lp").
std::string Slug(const std::string& label);

}  // namespace rths::studies
