#include "supervisor/in_process_group.h"

#include <optional>

#include "participants/replay.h"

namespace rths::supervisor {

std::vector<participants::Outcome> RunInProcessGroup(const scenario::Scenario& s, const ReplaySource* replay,
                                                     const ExternalRoles* external, const std::string& udpm_url,
                                                     std::int64_t run_id, const std::string& out_dir,
                                                     const volatile std::sig_atomic_t* stop,
                                                     lockstep::RealtimeSetup* setup, lockstep::LiveSink* live) {
  const bool bridged = external && !external->roles.empty();
  // How long the user's participants may take to say HELLO: a copy of the scenario only then.
  std::optional<scenario::Scenario> waiting;
  if (bridged && external->join_timeout_s > 0) {
    waiting = s;
    waiting->lockstep.handshake_timeout_s = external->join_timeout_s;
  }
  const scenario::Scenario& joined = waiting ? *waiting : s;
  if (replay) {
    return participants::RunReplay(joined, *replay->record, replay->steps, replay->live, run_id, out_dir, stop,
                                   bridged ? external->roles : std::vector<std::string>{}, udpm_url);
  }
  if (s.realtime.enabled) {
    // Every built-in participant runs on this thread: the set-up is this process's.
    *setup = lockstep::EnterRealtime(s.realtime);
  }
  if (bridged) return participants::RunMixedGroup(joined, external->roles, udpm_url, run_id, out_dir, stop, live);
  return participants::RunGroupInProcess({s}, run_id, out_dir, {}, stop, live);
}

}  // namespace rths::supervisor
