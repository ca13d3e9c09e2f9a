#include "supervisor/in_process_group.h"

#include "participants/replay.h"

namespace rths::supervisor {

std::vector<participants::Outcome> RunInProcessGroup(const scenario::Scenario& s, const ReplaySource* replay,
                                                     std::int64_t run_id, const std::string& out_dir,
                                                     const volatile std::sig_atomic_t* stop,
                                                     lockstep::RealtimeSetup* setup) {
  if (replay) return participants::RunReplay(s, *replay->record, replay->steps, replay->live, run_id, out_dir, stop);
  if (s.realtime.enabled) {
    // Every participant runs on this thread: the set-up is this process's.
    *setup = lockstep::EnterRealtime(s.realtime.sched_fifo, s.realtime.priority, s.realtime.lock_memory);
  }
  return participants::RunGroupInProcess({s}, run_id, out_dir, {}, stop);
}

}  // namespace rths::supervisor
