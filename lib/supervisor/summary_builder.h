#pragma once
/// @file The one place a run's summary (summary.json) is built: from the request, the plan, the
/// participants' outcomes and the run's log, for `rths run` and for every run of a study.
#include <csignal>
#include <optional>
#include <string>
#include <vector>

#include "lockstep/realtime.h"
#include "participants/group.h"
#include "supervisor/run_summary.h"
#include "supervisor/request.h"
#include "supervisor/teardown.h"

namespace rths::supervisor {

/// How the group ended, as the supervisor saw it.
struct GroupEnd {
  std::vector<participants::Outcome> outcomes;
  double wall_s = 0.0;                    ///< [s] start to end of the group
  bool interrupted = false;               ///< stopped by the user (SIGINT / SIGTERM)
  std::optional<Clock::time_point> noticed;  ///< udpm: when the failure was noticed (teardown_s)
  lockstep::RealtimeSetup memq_setup;     ///< memq, paced: what this process got
};

/// The summary's fields known before the run: label, scenario, hash, run id, transport, URL,
/// steps expected, output estimate (`rths run` only: the URL and estimate).
RunSummary SummaryHead(const RunRequest& request, const RunPlan& plan);

/// The whole summary: the head, wall time, the log's steps and figures (J1-J9 with a
/// reference_file), the outcomes and the verdict, the teardown time and, for a paced run, the
/// real-time figures. A study's run that did not complete every step is marked failed (StudyError).
RunSummary BuildSummary(const RunRequest& request, const RunPlan& plan, const GroupEnd& end);

/// Why a study's run does not count ("" if it does): the participant to blame and its message,
/// an unreadable log, or missing steps.
std::string StudyError(const RunSummary& sum);

/// Marks a study's run that failed with `error`: "stopped" says why; a run the verdict judged
/// completed becomes failed (exit code kExitLockstep), another verdict's status stands (a safety
/// stop stays "stopped by the safety monitor", as in `rths run`).
void MarkStudyFailure(const std::string& error, RunSummary* sum);

}  // namespace rths::supervisor
