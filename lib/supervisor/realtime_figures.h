#pragma once
/// @file A paced run's real-time figures for summary.json "realtime" (docs/realtime.md): the
/// clock's latency percentiles and deadline misses, and what each process got of SCHED_FIFO and
/// mlockall.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lockstep/realtime.h"
#include "participants/group.h"
#include "scenario/scenario.h"

namespace rths::supervisor {

/// The clock's latency figures (from whichever outcome has them) plus the set-up counts: on memq
/// `memq_setup` (this process, every participant), on udpm each participant's own.
nlohmann::json RealtimeFigures(const scenario::Scenario& s, const std::vector<participants::Outcome>& outcomes,
                               const std::string& transport, const lockstep::RealtimeSetup& memq_setup);

}  // namespace rths::supervisor
