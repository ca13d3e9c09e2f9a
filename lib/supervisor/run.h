#pragma once
/// @file One lockstep run, start to end: the supervisor behind `rths run`, the studies' batches
/// and the tests (docs/lockstep.md).
///
/// Checks what can be checked before a byte is written (the scenario builds, the multicast route,
/// the free disk space), makes the output folder with the scenario that runs and a reserved
/// summary.json (so a full disk cannot take it), starts the five participants — as processes on
/// udpm:// (one UDP port per run, ttl=0) or in this process on memq:// — and waits for them. A
/// participant that dies is noticed at once; the others are stopped (supervisor/teardown.h). At the
/// end it writes summary.json (supervisor/summary_builder.h), naming the participant to blame.
#include "supervisor/request.h"

namespace rths::supervisor {

/// Makes the run `request` asks for and returns its summary (also for a run that failed: the
/// summary's exit_code and failure say how). Throws RunError when it cannot start (kExitUsage:
/// nothing ran, the folder it made removed) or the group cannot run (kExitLockstep).
RunResult Run(const RunRequest& request);

}  // namespace rths::supervisor
