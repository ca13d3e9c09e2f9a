#pragma once
/// @file Every exit code of rths, in one table (docs/lockstep.md "Exit codes", the README and
/// `rths --help`; each tool's --help footer says which of them it uses). The numbers are part of
/// the interface: scripts and tests rely on them.
namespace rths::lockstep {

/// Of `rths run` (and replay), of each participant process, and of every tool for a bad command line.
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,          ///< bad command line or scenario, or not enough disk (nothing ran)
  kExitLockstep = 3,       ///< a protocol failure (a participant stopped answering, hash mismatch)
  kExitPeerAbort = 4,      ///< stopped because another participant (or the supervisor) said ABORT
  kExitInternal = 5,       ///< an exception in this participant's own computation
  kExitSafety = 6,         ///< the safety monitor stopped the run (a limit was left)
  kExitOutput = 7,         ///< the run's output could not be written (disk full, I/O error)
  kExitRealtime = 8,       ///< real-time mode: the miss policy stopped the run (docs/realtime.md)
  kExitExternalAbort = 9,  ///< an external participant (`--external`) stopped the run with ABORT
  /// an external participant was lost: its heartbeats stopped, or its process ended with a status
  /// rths could not read or with code 0 before the run's end (docs/participant.md, "Liveness")
  kExitExternalLost = 10,
  /// a participant in follow mode (`--follow`, docs/replay.md) answered the whole feed, but not
  /// every step exactly: some were answered from a held input, after one, or never seen
  kExitFollowInexact = 11,
};

/// Of the tools that read a run's log: `rths log` (stats, digest, dump, compare) and `rths export`.
enum LogExitCode : int {
  kLogOk = 0,               ///< every log complete (compare: identical payloads per (channel, k))
  kLogDiffer = 1,           ///< log compare: the logs differ
  kLogInternal = 1,         ///< export: an internal failure
  kLogBadInput = kExitUsage,  ///< not a readable LCM log of a run (or a usage error)
  kLogTruncated = 3,        ///< a log read but truncated (the run did not finish)
};

}  // namespace rths::lockstep
