#pragma once
/// @file A deterministic lockstep replay of a recorded run into live participants
/// (`rths replay`, docs/replay.md).
///
/// The roles named live run as usual (built from the scenario); each absent role is played by a
/// stand-in that answers step k with the message recorded for step k, re-stamped with the new
/// run id: a recorded clock (integrator absent) issues the recorded desired_t k once the barrier
/// of step k-1 is complete; a recorded controller, plant or semiactive answers step k when
/// desired_t k (the request) arrives. The logger is always live, so the replay writes a log of
/// its own. Everything else (handshake, barrier, repair of lost messages, the answer caches) is
/// the ordinary protocol, so a live participant cannot tell a replay from a test.
#include <string>
#include <vector>

#include "io/run_log.h"
#include "participants/group.h"
#include "scenario/scenario.h"

namespace rths::participants {

/// The channel a role answers on (lockstep::kRoster); throws rths::Error for a role that cannot be
/// live in a replay (the logger always is).
const char* AnswerChannelOf(std::string_view role);

/// Replays steps 0..steps-1 of `record` (steps <= record.CompleteSteps()) in this process on the
/// in-process queue, with the roles in `live` built from `s`, the others fed from the record; the
/// new log goes to `out_dir`. The live roles in `external` are not built: the user runs them, and
/// the queue is bridged to them on `udpm_url` (lockstep/bridge.h). Throws rths::Error (unknown
/// role, an external role that is not live, a recorded step missing, unwritable output, a bridge
/// that cannot open the URL).
std::vector<Outcome> RunReplay(const scenario::Scenario& s, const io::RunLog& record, std::int64_t steps,
                               const std::vector<std::string>& live, std::int64_t run_id, const std::string& out_dir,
                               const volatile std::sig_atomic_t* stop = nullptr,
                               const std::vector<std::string>& external = {}, const std::string& udpm_url = "");

}  // namespace rths::participants
