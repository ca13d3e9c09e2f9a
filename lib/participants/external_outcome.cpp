// ExternalOutcome (participants/group.h): an external participant's end, as the clock saw it.
#include <cstring>

#include <fmt/core.h>

#include "core/exit_code.h"
#include "participants/group.h"

namespace rths::participants {

Outcome ExternalOutcome(const std::string& role, const Outcome* clock) {
  Outcome o;
  o.role = role;
  o.external = true;
  const auto it = clock ? clock->peers.find(role) : decltype(clock->peers.end()){};
  if (!clock || it == clock->peers.end()) {
    o.observed = "unknown";
    return o;
  }
  const lockstep::PeerObservation& p = it->second;
  // Its link counters as the clock saw them: what it answered, the copies, what had to be
  // re-requested of it, and what it asked for.
  o.stats_known = true;
  o.stats.rerequests = p.rerequests;
  o.stats.repair_requests = p.repair_requests;
  o.stats.duplicates = p.duplicates;
  o.step = clock->step;
  if (p.aborted) {
    o.observed = "aborted";
    o.exit_code = rths::kExitExternalAbort;
    o.message = fmt::format("{} (external) aborted the run: {}", role, p.abort_reason);
    return o;
  }
  if (!p.hello) {
    o.observed = "never joined";
    o.exit_code = clock->culprit == role ? rths::kExitLockstep : 0;
    o.message = clock->culprit == role ? clock->message : "";
    return o;
  }
  if (p.lost) {
    const lockstep::PeerLoss& l = p.loss;
    o.message = fmt::format("{} (external) was lost: {}", role, l.what);
    if (l.died && l.status_known && l.signal != 0) {
      o.observed = "killed";
      o.signal = l.signal;
      o.exit_code = 128 + l.signal;
    } else if (l.died && l.status_known && l.exit_code != 0) {
      o.observed = "exited";
      o.exit_code = l.exit_code;
    } else {
      o.observed = "lost";
      o.exit_code = rths::kExitExternalLost;
    }
    return o;
  }
  if (p.bye) {
    o.observed = "finished";
    return o;
  }
  if (clock->exit_code == rths::kExitLockstep && clock->culprit == role) {
    o.observed = "silent";
    o.exit_code = rths::kExitLockstep;
    o.message = clock->message;
    return o;
  }
  o.observed = clock->exit_code == 0 ? "finished" : "stopped";
  o.exit_code = clock->exit_code == 0 ? 0 : rths::kExitPeerAbort;
  return o;
}

}  // namespace rths::participants
