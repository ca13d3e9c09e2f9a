#pragma once
/// @file Every exit code of every rths program, in one table (docs/lockstep.md "Exit codes", the
/// README and `rths --help`; each tool's --help footer says which of them it uses). A number means
/// one thing whichever program returns it; the numbers are part of the interface: scripts and
/// tests rely on them (tests/programs/exit_code_test.cpp checks that they are distinct).
namespace rths {

/// The exit codes. Meanings shared by several programs are said once here (1: the diff/grep
/// convention; 2: bad input; 5: an internal failure).
enum ExitCode : int {
  kExitOk = 0,
  /// The program ran to its end and its answer is "no" (as diff and grep exit 1): `rths log
  /// compare` and `rths replay`: the outputs differ; `rths sweep`: some runs did not complete
  /// (their rows say why).
  kExitNegative = 1,
  /// Bad command line, scenario or input file (named), or not enough free disk: nothing ran.
  kExitUsage = 2,
  kExitLockstep = 3,       ///< a protocol failure (a participant stopped answering, hash mismatch)
  kExitPeerAbort = 4,      ///< stopped because another participant (or the supervisor) said ABORT
  /// The program failed in its own work, not on bad input: an exception in a participant's
  /// computation; a tool that could not make its output (gnuplot missing or failing, a file it
  /// could not write) or hit an internal error. (A tool's was 1 before issue 45, = kExitNegative.)
  kExitInternal = 5,
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
  /// `rths log` (stats, digest, dump) and `rths export`: a log was read but is truncated (the run
  /// did not finish); its complete steps were used. (3 before issue 45: it collided with
  /// kExitLockstep.)
  kExitTruncated = 12,
  /// `rths identify --damper`: the fit failed (ident/fit_status.h: not converged, or a parameter on
  /// a bound), unless --accept-unconverged. (3 before issue 45: it collided with kExitLockstep.)
  kExitFitFailed = 13,
  /// 128 + N: a participant process was killed by signal N (the shell's convention).
  kExitSignalBase = 128,
  /// Interrupted (Ctrl-C, SIGTERM): the program stopped cleanly (128 + SIGINT).
  kExitInterrupted = 130,
};

/// Every code of ExitCode with its name, in value order (kExitSignalBase stands for 128 + N):
/// the table the tests check for distinct values.
struct ExitCodeEntry {
  const char* name;
  int code;
};
inline constexpr ExitCodeEntry kExitCodeTable[] = {
    {"ok", kExitOk},
    {"negative", kExitNegative},
    {"usage", kExitUsage},
    {"lockstep", kExitLockstep},
    {"peer_abort", kExitPeerAbort},
    {"internal", kExitInternal},
    {"safety", kExitSafety},
    {"output", kExitOutput},
    {"realtime", kExitRealtime},
    {"external_abort", kExitExternalAbort},
    {"external_lost", kExitExternalLost},
    {"follow_inexact", kExitFollowInexact},
    {"truncated", kExitTruncated},
    {"fit_failed", kExitFitFailed},
    {"signal_base", kExitSignalBase},
    {"interrupted", kExitInterrupted},
};

}  // namespace rths
