#pragma once
/// @file Reads a run's LCM event log (log.lcm) back into per-step records, for summaries,
/// replays and the lockstep regression tests. Runs are compared by decoded payload per
/// (channel, k): header timestamps are wall-clock and never compared.
#include <cstdint>
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

  /// Steps 0..n-1 for which every per-step channel has its message.
  std::int64_t CompleteSteps() const;
  /// The ABORT reason in the log ("" if none).
  std::string AbortReason() const;
};

/// Reads `path`; throws rths::Error if it cannot be opened or an event cannot be decoded.
RunLog ReadRunLog(const std::string& path);

/// Hex SHA-256 over the payloads of every step channel, channel by channel (sorted by name),
/// k ascending: equal digests mean bit-identical decoded payloads per (channel, k).
std::string PayloadDigest(const RunLog& log);

}  // namespace rths::io
