#pragma once
/// @file Reads a run's LCM event log (log.lcm) back into per-step records, for summaries,
/// replays and the lockstep regression tests. Runs are compared by decoded payload per
/// (channel, k): header timestamps are wall-clock and never compared.
///
/// The reader trusts nothing in the file (io/event_log.h EventLogReader): garbage, a payload that
/// does not decode as its channel's type, a negative step index or one that cannot belong to the
/// log is an rths::Error naming the file and the byte offset of the event. A log that ends early
/// is not an error: RunLog says whether the clock's DONE is in it (the run finished) and where a
/// cut-short last event starts, and CompleteSteps() says up to which step it is valid.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/handshake_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::io {

struct RunLog {
  std::int64_t run_id = 0;
  /// Messages by step index k (a missing step has k = -1).
  std::vector<rths::desired_t> desired;
  std::vector<rths::command_t> command;
  std::vector<rths::measured_t> measured;
  std::vector<rths::current_t> current;
  std::vector<rths::handshake_t> handshakes;  ///< in log order
  /// Messages per step channel, and repeated (channel, k) pairs (must be 0: the logger
  /// commits one message per (channel, k)).
  std::map<std::string, std::int64_t> count, duplicates;
  /// Payload bytes per (channel, k) with run_id zeroed (it differs between runs by design),
  /// for bit-for-bit comparison of runs.
  std::map<std::string, std::vector<std::vector<std::uint8_t>>> payload;
  /// Wall-clock receive times [us] of the first and last desired_t (for steps/s).
  std::int64_t first_desired_utime = 0, last_desired_utime = 0;
  /// Events on channels this reader does not know.
  std::int64_t unknown_events = 0;

  /// The file's path (or the buffer's name) and size [bytes], and its complete events.
  std::string source;
  std::uint64_t file_bytes = 0;
  std::int64_t events = 0;
  /// Steps the run planned (the largest n_steps of its handshakes; 0 if no handshake says).
  std::int64_t n_steps = 0;
  /// True if the log holds the clock's DONE handshake (phase 5): every step was committed and the
  /// run finished. A log without it is truncated: the run did not finish (aborted, killed, disk
  /// full); its complete steps are still valid.
  bool done = false;
  /// True if the file ends in the middle of an event (a write cut short); that event starts at
  /// truncated_at_byte and is ignored, everything before it is read.
  bool truncated_tail = false;
  std::uint64_t truncated_at_byte = 0;
  /// True if the file ends in space the logger reserved and did not cut back (it was killed,
  /// io::MappedLogFile): the log ends at zero_tail_at_byte, everything before it is whole.
  bool zero_tail = false;
  std::uint64_t zero_tail_at_byte = 0;

  /// Steps 0..n-1 for which every per-step channel has its message.
  std::int64_t CompleteSteps() const;
  /// The step of the lockstep clock [s] the handshakes carry (the first positive, finite dt_s);
  /// 0 if no handshake says.
  double StepS() const;
  /// The scenario hash the participants announced: the first handshake's non-empty
  /// scenario_sha256 ("" if no handshake says). The one reading of it (export, replay).
  std::string ScenarioSha256() const;
  /// The ABORT reason in the log ("" if none).
  std::string AbortReason() const;
  /// True if the run finished and its log is whole: DONE is in it and no event is cut short.
  bool Complete() const { return done && !truncated_tail; }
  /// Why the log is not Complete() ("" if it is): "truncated (the run did not finish: no DONE
  /// handshake)" and/or "the file ends in the middle of an event at byte N".
  std::string TruncationReason() const;
};

/// What a run achieved, computed from its log over its complete steps.
struct RunMetrics {
  std::int64_t steps = 0;                  ///< complete steps
  double tracking_nrmse_pct = 0.0;         ///< Eq. 31 between r_k and y_k
  double peak_force_kN = 0.0;              ///< max |f_k|
  double peak_displacement_mm = 0.0;       ///< max |y_k|
  /// Eq. 20's extrapolated acceleration r''_k against the acceleration of sample k known one
  /// step later (a_{k} = acc_prev of desired_t k+1), as Eq. 31's norm [%] (paper: 1.81 %).
  double accel_extrapolation_rms_err_pct = 0.0;
  /// Eq. 21's predicted velocity r'_k against v_k one step later [%] (paper: 0.0061 %).
  double velocity_prediction_rms_err_pct = 0.0;
  /// Steps per second of log time, from the desired_t timestamps: 1/dt for logs written by our
  /// logger (simulated time), the recording pace for logs of other recorders (lcm-logger).
  double steps_per_s = 0.0;
};
RunMetrics ComputeMetrics(const RunLog& log);

/// The log.lcm of a run folder (RUN_DIR of rths run or rths replay). Throws rths::Error naming
/// `run_dir`: it does not exist, it is a file (log.lcm itself given: "give its folder"), or it
/// holds no log.lcm.
std::filesystem::path RunFolderLog(const std::filesystem::path& run_dir);

/// Reads `path`. Throws rths::Error (where = path, problem "byte N: ...") if it cannot be opened,
/// is empty or not an LCM event log, or an event is corrupt: a payload that does not decode
/// exactly as its channel's type (RTHS_HANDSHAKE, RTHS_DESIRED, RTHS_COMMAND, RTHS_MEASURED,
/// RTHS_CURRENT; other channels are counted in unknown_events), a step index k < 0, or a k that
/// cannot belong to this log (k >= the handshake's n_steps, or k >= the number of events in the
/// file). A log that ends early is read up to where it ends (RunLog::done, truncated_tail).
RunLog ReadRunLog(const std::string& path);
/// ReadRunLog on a log in memory (`name` names it in messages); for tests and fuzzing.
RunLog ReadRunLogBytes(const std::string& name, const std::uint8_t* bytes, std::size_t size_bytes);

/// Hex SHA-256 over the payloads of every step channel, channel by channel (sorted by name),
/// k ascending: equal digests mean bit-identical decoded payloads per (channel, k).
std::string PayloadDigest(const RunLog& log);

}  // namespace rths::io
