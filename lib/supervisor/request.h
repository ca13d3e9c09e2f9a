#pragma once
/// @file What a run is asked to be (RunRequest), what it became (RunResult) and how it can fail
/// before it ends (RunError): the supervisor's interface, for `rths run`, the studies' batch
/// runner (studies/batch.h) and tests (docs/lockstep.md).
#include <algorithm>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/run_log.h"
#include "lockstep/live_feed.h"
#include "supervisor/run_summary.h"
#include "scenario/scenario.h"
#include "supervisor/disk.h"

namespace rths::supervisor {

/// What `rths run --external` changes: the roles the user runs, and how long everyone waits for
/// them.
struct ExternalRoles {
  std::vector<std::string> roles;
  double join_timeout_s = 0;  ///< [s] 0: the scenario's lockstep.handshake_timeout_s
  bool has(const std::string& role) const { return std::find(roles.begin(), roles.end(), role) != roles.end(); }
};

/// A replay (participants/replay.h): the roles in `live` are built from the scenario, the others
/// answer steps 0..steps-1 from `record`.
struct ReplaySource {
  const io::RunLog* record = nullptr;  ///< the recorded run (outlives the run)
  std::int64_t steps = 0;              ///< <= record->CompleteSteps()
  std::vector<std::string> live;
};

/// What has been decided before the run starts (passed to RunRequest::on_start).
struct RunPlan {
  scenario::Scenario scenario;        ///< the scenario that runs (loaded back from the folder's file if written)
  std::string scenario_path;          ///< the file the participants read
  std::string url;                    ///< udpm, mixed: the run's LCM URL; memq: "memq://"
  std::int64_t run_id = 0;
  std::filesystem::path out;          ///< the output folder
  OutputEstimate sizes;               ///< what the run will write
  bool created_out = false;           ///< the folder did not exist before the run
};

/// One run to make.
struct RunRequest {
  scenario::Scenario scenario;        ///< loaded, `--set` overrides applied
  std::string scenario_path;          ///< the file it was loaded from ("" for a scenario built in code)
  /// How out/scenario.toml is made: "" copies scenario_path; otherwise the scenario is written out
  /// in full (scenario::ToToml) under the comment line "# <scenario_header>" and loaded back, so
  /// its hash is the file's, and the participants read that file.
  std::string scenario_header;
  /// "udpm": one process per participant; "memq": every participant in this process; "mixed":
  /// the built-in participants in this process, bridged to the external ones on udpm
  /// (lockstep/bridge.h; needs `external`).
  std::string transport = "udpm";
  std::string lcm_url;                ///< udpm: "" picks udpm://239.255.76.67:<a free port>?ttl=0
  bool port_per_channel = false;      ///< udpm with a picked URL: a free port per channel
  std::filesystem::path out;          ///< the output folder ("" a new one under runs/)
  std::filesystem::path bin_dir;      ///< udpm: where the rths-<role> programs are
  std::int64_t run_id = 0;            ///< 0: a new random id
  ExternalRoles external;             ///< udpm, mixed: roles the user runs
  std::vector<std::string> role_args; ///< udpm: extra arguments for every participant process
  /// Check before a byte is written that the scenario builds, the transport can carry it, the
  /// folder is new or empty and (check_disk_space) the disk has room. Off for a study's batch and a
  /// replay: they check beforehand. (RunRequest::IsValid is checked always.) Was `checks`.
  bool check_before_start = true;
  bool check_disk_space = true;       ///< refuse a run that will not fit on the disk
  /// Never remove the output folder, also of a run that could not start (a study's batch,
  /// studies::RunBatch: the folder is the study's record of the run). Was half of `study`.
  bool keep_folder = false;
  /// The summary of a batch's run (supervisor/summary_builder.h): the label, neither the URL nor
  /// the output estimate, and a run that did not complete every step marked failed. Was the other
  /// half of `study`.
  bool batch_summary = false;
  std::optional<ReplaySource> replay;  ///< memq: replay a recorded run instead
  /// The summary's file in the output folder, reserved before the run and written at its end
  /// ("": none; a replay writes replay.json, supervisor/replay_report.h).
  std::string summary_file = "summary.json";
  std::string label;                  ///< a study's run label (summary.json "label")
  bool progress = false;              ///< draw the run's progress on stderr (ProgressLine)
  /// Set it (a signal handler) to stop the run; udpm runs also set it on SIGINT / SIGTERM.
  /// Null: the run cannot be interrupted.
  volatile std::sig_atomic_t* interrupted = nullptr;
  /// memq, mixed: the clock's live records go there (a monitor in this process,
  /// lockstep/live_feed.h); udpm runs publish them on the run's URL instead. Not owned.
  lockstep::LiveSink* live_sink = nullptr;
  std::function<void(const std::string&)> on_warning;  ///< e.g. "this run will write about 3 GB"
  /// Called once, just before the participants start; if it throws, nothing runs (RunError,
  /// kExitUsage, the folder made for the run removed).
  std::function<void(const RunPlan&)> on_start;

  /// Whether the transport, the URL, the external roles, the port per channel, the live sink
  /// (`--watch` in this process) and a replay go together: the one place of these rules, for
  /// `rths run`, `rths replay` and supervisor::Run. If not, *why (if given) says which, naming the
  /// command-line flags ("--external needs the mixed (default) or udpm transport ...").
  ///   - transport is udpm, memq or mixed;
  ///   - --external: mixed or udpm (an external process cannot join memq); mixed needs --external;
  ///   - --lcm-url: udpm or mixed, a valid udpm:// URL (lockstep::UdpmUrl);
  ///   - --port-per-channel (or a URL with port_per_channel=1): udpm only (a mixed run bridges on
  ///     one port);
  ///   - a live sink (--watch fed in this process): memq or mixed (a udpm run's monitor listens to
  ///     its URL);
  ///   - a replay: memq, or mixed with --external.
  bool IsValid(std::string* why = nullptr) const;
};

/// A finished run (also one that failed: its summary says how).
struct RunResult {
  RunSummary summary;   ///< as written to out/summary.json
  RunPlan plan;
  bool summary_written = false;       ///< false: the summary file could not be written (or none was asked for)
};

/// A run that could not be made or could not finish: exit_code kExitUsage (nothing ran; the
/// folder made for it removed) or kExitLockstep (the group could not run). `summary` holds what
/// was known.
class RunError : public Error {
 public:
  RunError(int exit_code, const std::string& what, RunSummary summary)
      : Error("", what), exit_code_(exit_code), summary_(std::move(summary)) {}
  int exit_code() const { return exit_code_; }
  const RunSummary& summary() const { return summary_; }

 private:
  int exit_code_;
  RunSummary summary_;
};

}  // namespace rths::supervisor
