#pragma once
/// @file The lockstep runtime's knobs (docs/lockstep.md): the scenario's [lockstep] table, and the
/// clock's pacing from its [realtime] table (set at the edge, participants::LockstepOf).
#include "lockstep/realtime.h"

namespace rths::lockstep {

/// Lockstep runtime knobs (ranges in docs/scenarios.md).
struct LockstepConfig {
  /// The longest silence before the clock re-requests an incomplete step [ms], [5, 10000]. When
  /// steps are fast it re-requests sooner: after 8 typical step times, at least kMinRerequestS.
  /// Each further re-request of the same step waits twice as long, up to max(rerequest_ms, 1000 ms).
  double rerequest_ms = 100.0;
  /// A step that has not completed after this long [s], [1, 3600] and at least 4 rerequest_ms,
  /// stops the run, naming who stopped answering. A loaded host only slows steps down.
  /// Participants give up on a silent clock after stall_budget_s + 2 s.
  double stall_budget_s = 10.0;
  double handshake_timeout_s = 20;  ///< wait for every HELLO (clock) / for GO (others) [s], [0.1, 600]
  /// The clock's real-time pacing ([realtime]; off: as fast as the participants answer). Not a
  /// key of [lockstep]: filled in from [realtime] and run.dt_s.
  Pacing pacing;
  /// Not keys of [lockstep] either: what a participant declares in its HELLO (docs/participant.md,
  /// "Liveness"). Its pid, for the clock to watch: only on the clock's host (a participant process
  /// gives it when its URL has ttl=0, in-process ones always; the clock ignores its own process's).
  bool announce_pid = true;
  /// The period of its HEARTBEATs [s] (0: none), e.g. from another host (`--heartbeat-s`).
  double heartbeat_s = 0;

  /// The shortest wait before a first re-request [s].
  static constexpr double kMinRerequestS = 1e-3;
  /// Wait before re-request number `n` (1-based) of one step [s], when a step typically takes
  /// `typical_step_s` (0 if not known yet).
  double RerequestAfterS(int n, double typical_step_s) const;
  /// How long a participant that heard nothing from the clock keeps waiting [s].
  double WatchdogS() const { return stall_budget_s + 2.0; }
  /// How long a participant lingers after DONE, answering repeated DONEs, without CLOSE [s].
  double LingerS() const;
  bool operator==(const LockstepConfig&) const = default;
};

}  // namespace rths::lockstep
