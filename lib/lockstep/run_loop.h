#pragma once
/// @file The event loop of one or more participants on one transport (docs/lockstep.md).
#include <csignal>
#include <functional>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lockstep/participant.h"

namespace rths::lockstep {

/// Runs participants sharing one LCM instance until every one has finished. In udpm mode the
/// vector holds one participant; in memq mode all of them. Returns the first non-zero exit
/// code of a participant that failed on its own (not kExitPeerAbort), else the first
/// non-zero, else 0.
/// When `*stop` becomes true (an interrupt), every participant stops at once (exit
/// kExitPeerAbort, "interrupted"), its committed output flushed.
int RunLoop(lcm::LCM* lcm, const std::vector<Participant*>& participants,
            const volatile std::sig_atomic_t* stop = nullptr);
/// RunLoop over any transport: `handle(timeout_ms)` waits at most that long and handles what
/// came in, returning as lcm::LCM::handleTimeout does (> 0 handled, 0 timed out, < 0 error).
int RunLoopWith(const std::function<int(int)>& handle, const std::vector<Participant*>& participants,
                const volatile std::sig_atomic_t* stop = nullptr);

}  // namespace rths::lockstep
