#pragma once
/// @file A participant group in this process (the memq transport): every participant on this
/// thread, on the group's own memq:// instance (participants/group.h), or a replay of a recorded
/// run (participants/replay.h).
#include <csignal>
#include <cstdint>
#include <string>
#include <vector>

#include "lockstep/realtime.h"
#include "participants/group.h"
#include "scenario/scenario.h"
#include "supervisor/request.h"

namespace rths::supervisor {

/// Runs the group of `s` in this process (a replay of `replay` if not null; a mixed run, bridged
/// to the `external` roles on `udpm_url`, if `external` is not null and names any); out_dir
/// receives log.lcm and signals.csv. A paced run (s.realtime.enabled, not a replay) first asks
/// for SCHED_FIFO / mlockall for this process and says what it got in *setup. `stop` (optional)
/// interrupts the run; `live` (optional, not a replay) receives the clock's live records. Throws
/// rths::Error as RunGroupInProcess, RunMixedGroup and RunReplay.
std::vector<participants::Outcome> RunInProcessGroup(const scenario::Scenario& s, const ReplaySource* replay,
                                                     const ExternalRoles* external, const std::string& udpm_url,
                                                     std::int64_t run_id, const std::string& out_dir,
                                                     const volatile std::sig_atomic_t* stop,
                                                     lockstep::RealtimeSetup* setup, lockstep::LiveSink* live = nullptr);

}  // namespace rths::supervisor
