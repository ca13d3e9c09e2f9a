#pragma once
/// @file Stopping a process group after a failure: ABORT broadcast to every participant, then,
/// for whoever has not stopped after a grace time, SIGTERM, then SIGKILL (docs/lockstep.md,
/// "Failures").
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <string>

namespace rths::supervisor {

using Clock = std::chrono::steady_clock;

/// After a failure: time the others get to stop by themselves after ABORT, then after SIGTERM.
inline constexpr auto kGraceAbort = std::chrono::milliseconds(1000);
inline constexpr auto kGraceTerm = std::chrono::milliseconds(1000);

/// The state letter of /proc/PID/stat ('T': stopped), or 0.
char ProcessState(pid_t pid);

/// The teardown's clock: started once (ABORT broadcast), it says when the survivors are due a
/// SIGTERM and then a SIGKILL.
class Teardown {
 public:
  Teardown(std::string url, std::int64_t run_id) : url_(std::move(url)), run_id_(run_id) {}
  /// Broadcasts ABORT with `reason` and starts the grace time (once; later calls do nothing).
  void Start(const std::string& reason);
  /// How long to wait for the next event [ms]: until the next escalation, or `idle_ms`.
  int WaitMs(int idle_ms) const;
  /// The signal the survivors are due now (SIGTERM, then SIGKILL, each once), or 0.
  int Due();
  bool started() const { return started_; }
  Clock::time_point noticed() const { return noticed_; }  ///< when Start was first called

 private:
  std::string url_;
  std::int64_t run_id_;
  bool started_ = false, termed_ = false, killed_ = false;
  Clock::time_point noticed_{}, term_at_{}, kill_at_{};
};

}  // namespace rths::supervisor
