#pragma once
/// @file What a replay found (docs/replay.md): every live role's output channel compared with the
/// recording, and replay.json.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "participants/group.h"

namespace rths::supervisor {

/// A finished replay, compared with its recording.
struct ReplayReport {
  bool failed = false;                ///< the replay run failed or was interrupted
  participants::Verdict verdict;      ///< whom to blame if it failed
  bool interrupted = false;
  bool compared = false;              ///< the replay's log was read and compared
  bool identical = false;             ///< every live channel equals the recording (if compared)
  std::int64_t replayed = 0;          ///< complete steps in the replay's log
  std::vector<std::string> lines;     ///< per live role: "live ROLE: <ChannelDiff described>"
  std::string log_error;              ///< why the replay's log could not be read
  nlohmann::json json;                ///< replay.json without "exit_code" and the final "status"

  /// replay.json: `json` with the command's exit code and, for a replay that did not fail,
  /// status "completed".
  nlohmann::json ToJson(int exit_code) const;
};

/// What to record about the replay before it ran.
struct ReplayFacts {
  std::string run_dir;                ///< the recorded run's folder
  std::vector<std::string> live;
  std::int64_t steps = 0;             ///< steps asked for
  std::string scenario_sha256;        ///< the live participants' scenario
  std::string recorded_scenario_sha256;  ///< the recording's ("" if its log has no handshake)
};

/// Judges the replay's outcomes and compares each live role's answer channel in out/log.lcm with
/// `record`; never throws (an unreadable log is in log_error).
ReplayReport CompareReplay(const ReplayFacts& facts, const io::RunLog& record, const std::filesystem::path& out,
                           const std::vector<participants::Outcome>& outcomes, bool interrupted);

}  // namespace rths::supervisor
