#pragma once
/// @file All five participants of a run in this process, on one memq:// LCM instance: what
/// `rths run --transport memq` does, and what the reproduction studies and tests use to run
/// many groups side by side (each group has its own instance, so they cannot cross-talk).
/// Also how a run's outcomes are judged: who is to blame when it fails.
#include <csignal>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "lockstep/faults.h"
#include "lockstep/link_stats.h"
#include "lockstep/live_feed.h"
#include "lockstep/participant.h"
#include "lockstep/realtime.h"
#include "scenario/scenario.h"

namespace rths::participants {

/// Test-only faults for one role, on top of the scenario's [faults] (targeted faults, a
/// controller sign error).
struct RoleFault {
  std::string role;
  lockstep::Faults faults;
};

/// How one participant ended.
struct Outcome {
  std::string role;
  int exit_code = 0;     ///< ExitCode (core/exit_code.h), or 128 + signal for a process
  int signal = 0;        ///< the signal that killed the process (0 if none)
  std::string message;   ///< why it failed ("" if it did not)
  std::string culprit;   ///< whom it blames for the failure ("" if none or itself)
  std::int64_t step = -1;  ///< the step it failed at (-1 if unknown or before step 0)
  bool killed_by_supervisor = false;  ///< the supervisor sent the signal that ended it
  bool was_stopped = false;           ///< ... while it was stopped (SIGSTOP, state T)
  bool stats_known = false;
  lockstep::LinkStats stats;
  double stepping_s = 0;  ///< the clock: wall-clock time from GO to the last committed step [s]
  /// The logger: steps whose signals.csv row waited for its writer thread (-1: not a logger).
  std::int64_t output_stalls = -1;
  bool external = false;  ///< run by the user (`rths run --external`): not started by us
  /// External: how its end was observed by the clock: "finished" (said BYE), "aborted" (sent ABORT
  /// with `message` as reason), "killed" (its process died by `signal`), "exited" (its process
  /// ended with `exit_code`), "lost" (heartbeats stopped, or an unreadable exit status), "silent"
  /// (stopped answering: the stall budget), "stopped" (told to stop by another's failure),
  /// "never joined" (no HELLO).
  std::string observed;
  lockstep::RealtimeSetup realtime_setup;  ///< paced runs: SCHED_FIFO / mlockall achieved
  /// The clock: what it saw of every participant of the roster (by role; empty for the others).
  std::map<std::string, lockstep::PeerObservation> peers;
  /// The clock: step latencies and deadline misses (realtime.paced false for the others).
  lockstep::RealtimeStats realtime;
  /// ... as read back from a participant process's outcome file (RealtimeToJson), if any.
  nlohmann::json realtime_json;
  /// Follow mode (`--follow`): what the participant did with every step (null otherwise):
  /// FollowToJson.
  nlohmann::json follow;
  /// The realtime JSON of either source (null if none).
  nlohmann::json RealtimeJson() const;
};
/// The clock's latency figures as JSON (summary.json "realtime"): percentiles and max [us],
/// misses, the non-empty histogram bins as [lower_us, upper_us, count].
nlohmann::json RealtimeToJson(const lockstep::RealtimeStats& r);
/// A follow-mode participant's ledger as JSON (its outcome file's "follow"): the counts `exact`,
/// `resumed`, `held`, `unseen` and `n_steps`, the `messages` of the run it heard, and the step ranges [first, last] of each class but
/// exact (`held_steps`, `resumed_steps`, `unseen_steps`; at most kFollowRangesKept each, with
/// `ranges_truncated` if more).
nlohmann::json FollowToJson(const lockstep::FollowLedger& ledger);
inline constexpr std::size_t kFollowRangesKept = 1000;
/// How a finished participant ended: its exit code, message, culprit, step, link statistics and
/// (the clock) its stepping time and latency figures. Keeps `base`'s other fields.
Outcome OutcomeOf(const lockstep::Participant& p, Outcome base = {});
nlohmann::json OutcomeToJson(const Outcome& o);
/// Reads what OutcomeToJson wrote; throws nlohmann::json::exception on a malformed object.
Outcome OutcomeFromJson(const nlohmann::json& j);
nlohmann::json StatsToJson(const lockstep::LinkStats& s);

/// Runs a whole group on memq://; `out_dir` receives log.lcm and signals.csv. `per_role` holds
/// one scenario for every role, or five, in lockstep::kBuildOrder (tests give one role another file).
/// Throws rths::Error if a participant cannot be built (bad model, unwritable output) or the
/// scenario asks for a process fault that would take this whole process down (crash, kill, stop).
/// `stop` (optional): set it (from a signal handler) to interrupt the run. `live` (optional): the
/// clock's live records go there (a monitor in this process, lockstep/live_feed.h).
std::vector<Outcome> RunGroupInProcess(const std::vector<scenario::Scenario>& per_role,
                                       std::int64_t run_id, const std::string& out_dir,
                                       const std::vector<RoleFault>& faults = {},
                                       const volatile std::sig_atomic_t* stop = nullptr,
                                       lockstep::LiveSink* live = nullptr);

/// The outcome of external participant `role` as the clock observed it (`clock`: the clock's
/// outcome, nullptr if unknown): how it ended (Outcome::observed), the exit code that stands for
/// it (its own 128 + signal or exit code when its process was watched; kExitExternalAbort,
/// kExitExternalLost; kExitLockstep when it stopped answering; kExitPeerAbort when it was told to
/// stop), the message, and its link counters as seen by the clock.
Outcome ExternalOutcome(const std::string& role, const Outcome* clock);

/// A mixed run (lockstep/bridge.h): every participant of `s` but the `external` roles in this
/// process, on one in-process queue bridged to the external participants on `udpm_url` (a plain
/// udpm:// URL). Throws as RunGroupInProcess, and if the bridge cannot open the URL.
std::vector<Outcome> RunMixedGroup(const scenario::Scenario& s, const std::vector<std::string>& external,
                                   const std::string& udpm_url, std::int64_t run_id, const std::string& out_dir,
                                   const volatile std::sig_atomic_t* stop = nullptr,
                                   lockstep::LiveSink* live = nullptr);

/// The outcome to blame for a failed run: one that failed on its own (a signal, an exception)
/// before one that detected a failure (lockstep) before one that was told to stop; nullptr if
/// every participant succeeded.
const Outcome* RootCause(const std::vector<Outcome>& outcomes);

/// A failed run, judged from every participant's outcome.
struct Verdict {
  bool failed = false;
  std::string role;          ///< the participant to blame
  int exit_code = 0;         ///< the run's exit code (ExitCode (core/exit_code.h) or 128 + signal)
  std::string what;          ///< one sentence: what happened to whom, at which step
  std::int64_t step = -1;    ///< the step it happened at (-1 if unknown)
};
/// Blame, in order: a participant killed by a signal the supervisor did not send (a crash or
/// an outside kill); one that failed on its own (its computation, the safety monitor, its
/// output); the participant a lockstep failure names as having stopped answering (with "the
/// supervisor killed it" when it had to); then whoever was told to stop. Participants that only
/// waited for the culprit are never blamed.
Verdict Judge(const std::vector<Outcome>& outcomes);

}  // namespace rths::participants
