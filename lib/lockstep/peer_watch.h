#pragma once
/// @file How the clock notices that a participant has gone (docs/participant.md, "Liveness"):
/// a participant on the clock's host gives its pid in HELLO and is watched like a child (a pidfd:
/// its death is seen within kCheckPeriodS); one on another host may declare a heartbeat period
/// in HELLO and is lost after kMissedBeats periods without a HEARTBEAT. Without either, only the
/// stall budget of a step it does not answer can tell (ClockParticipant::FailStalled says so).
///
/// The exit status of a process that is not our child is not ours to wait for; it is read from
/// the kernel's process-event connector (netlink, PROC_EVENT_EXIT) when this process may listen to
/// it (CAP_NET_ADMIN, e.g. root); otherwise the death is reported with an unknown status.
#include <sys/types.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "lockstep/protocol.h"
#include "lockstep/step_table.h"

namespace rths::lockstep {

/// How the end of a watched participant was observed.
struct PeerLoss {
  int role = -1;              ///< roster index
  bool died = false;          ///< its process ended (else: its heartbeats stopped)
  bool status_known = false;  ///< died: the exit status was read (exit_code / signal valid)
  int exit_code = 0;          ///< died, status known, not signalled: its exit code
  int signal = 0;             ///< died, status known: the signal that killed it (0 if none)
  double silent_s = 0;        ///< heartbeats: time since the last one [s]
  std::string what;           ///< one clause: "its process (pid 123) was killed by signal 9 (Killed)"
};

/// What the clock saw of one participant (summary.json: an external participant's outcome and
/// link counters "as seen by the clock").
struct PeerObservation {
  std::int32_t pid = 0;          ///< HELLO: its pid on the clock's host (0: none given)
  double heartbeat_s = 0;        ///< HELLO: its heartbeat period [s] (0: none)
  bool hello = false;            ///< it said HELLO
  bool bye = false;              ///< it said BYE (it finished the run)
  bool lost = false;             ///< `loss` holds how it went
  PeerLoss loss;
  std::string abort_reason;      ///< it sent ABORT with this reason (aborted = !abort_reason.empty())
  bool aborted = false;          ///< it sent ABORT
  std::int64_t answers = 0;            ///< its answers the clock's barrier received (first copies)
  std::int64_t duplicates = 0;         ///< further copies of them (ignored)
  std::int64_t rerequests = 0;         ///< re-requests of the clock that listed its answers
  std::int64_t repair_requests = 0;    ///< repair_t it sent (inputs it lacked)
};

class PeerWatch {
 public:
  /// Heartbeat periods missed before a participant is declared lost.
  static constexpr int kMissedBeats = 5;
  /// How often the pidfds are looked at [s] (a death is seen within this).
  static constexpr double kCheckPeriodS = 0.02;

  PeerWatch() { exit_status_.fill(-1); }
  ~PeerWatch();
  PeerWatch(const PeerWatch&) = delete;
  PeerWatch& operator=(const PeerWatch&) = delete;

  /// From the HELLO of roster entry `role`: watch process `pid` (if > 0 and not this process;
  /// a pid that does not exist is ignored) and expect a HEARTBEAT every `heartbeat_s` (if > 0).
  void Watch(int role, std::int32_t pid, double heartbeat_s, SteadyClock::time_point now);
  /// A HEARTBEAT (or any other sign of life: HELLO) from `role`.
  void Beat(int role, SteadyClock::time_point now);
  /// Stops watching `role` (it said BYE: it may exit now).
  void Forget(int role);
  /// The first watched participant found gone, or nullopt. Looks at most every kCheckPeriodS.
  std::optional<PeerLoss> Check(SteadyClock::time_point now);
  /// When Check() next has something to look at (time_point::max() if nothing is watched).
  SteadyClock::time_point NextCheck() const;

  /// What was declared in HELLO.
  std::int32_t pid(int role) const { return peers_[role].pid; }
  double heartbeat_s(int role) const { return peers_[role].heartbeat_s; }
  /// Whether `role` is watched by pid or heartbeat (so its loss is seen without the stall budget).
  bool watched(int role) const { return peers_[role].pidfd >= 0 || peers_[role].heartbeat_s > 0; }

 private:
  struct Peer {
    std::int32_t pid = 0;
    int pidfd = -1;
    double heartbeat_s = 0;
    SteadyClock::time_point last_beat{};
  };
  /// Opens the process-event connector (once); false if this process may not listen.
  bool OpenExitEvents();
  /// Reads every waiting process-exit event, keeping the status of watched pids.
  void DrainExitEvents();
  PeerLoss Died(int role);

  std::array<Peer, kRosterSize> peers_{};
  std::array<int, kRosterSize> exit_status_{};  ///< wait status from the connector, -1: not seen
  int events_fd_ = -1;                           ///< the connector's socket (-1: none)
  bool events_tried_ = false;
  SteadyClock::time_point next_check_ = SteadyClock::time_point::min();
};

}  // namespace rths::lockstep
