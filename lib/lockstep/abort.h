#pragma once
/// @file ABORT from outside the run's processes: the supervisor's teardown and the live monitor's
/// Abort button (docs/lockstep.md, "Failures"; docs/monitor.md).
#include <cstdint>
#include <string>

#include "lockstep/protocol.h"

namespace rths::lockstep {

/// The sender name of the live monitor's ABORT (docs/monitor.md).
inline constexpr const char* kMonitorSender = "monitor";

/// The handshake ABORT (phase 4) of run `run_id` from `sender`, with `reason` and the step `k`
/// being run (-1 if unknown), encoded: what BroadcastAbort and Participant::RelayAbort send.
Bytes EncodeAbort(std::int64_t run_id, const std::string& sender, const std::string& reason, std::int64_t k);

/// Tells every participant of run `run_id` to stop: a handshake ABORT (phase 4) on the run's udpm
/// `url` (a run with a port per channel: on the handshake channel's port), from `sender`, with
/// `reason` and the step `k` being run (-1 if unknown), sent 3 times (udpm may drop one). False
/// if the URL could not be opened.
bool BroadcastAbort(const std::string& url, std::int64_t run_id, const std::string& sender, const std::string& reason,
                    std::int64_t k = -1);

}  // namespace rths::lockstep
