#pragma once
/// @file A replay's pre-run check (`rths replay`, docs/replay.md): everything that can be refused
/// before anything runs — the live roles, the recording (a log with complete steps), the live
/// participants' scenario at the recording's step, the steps to replay and the output folder.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/run_log.h"
#include "scenario/scenario.h"

namespace rths::supervisor {

/// What the user asked for.
struct ReplayOptions {
  std::string run_dir;   ///< the recorded run's folder (log.lcm, scenario.toml)
  std::string live;      ///< --live ROLE[,ROLE...]
  std::string out;       ///< --out ("" a new folder under runs/)
  std::string scenario;  ///< --scenario ("" RUN_DIR/scenario.toml)
  std::int64_t steps = 0;  ///< --steps (0: every complete step of both)
};

/// What the replay will be, checked before anything runs.
struct ReplayPlan {
  std::vector<std::string> live;   ///< the live roles, in the order named, without repeats
  io::RunLog record;               ///< the recording
  std::string scenario_path;       ///< the live participants' scenario file
  scenario::Scenario scenario;     ///< loaded from it
  std::filesystem::path out;       ///< the output folder (new or empty)
  std::int64_t steps = 0;          ///< steps to replay
  std::string recorded_sha;        ///< the recording's scenario hash (io::RunLog::ScenarioSha256)
};

/// The live roles of `--live ROLE[,ROLE...]` (integrator, controller, plant, semiactive; not the
/// logger). Throws rths::Error ("--live") naming the allowed roles.
std::vector<std::string> LiveRoles(const std::string& arg);

/// Checks everything and returns the plan; throws rths::Error naming the file, flag or key. Notes
/// that are not errors (a truncated recording, a scenario of another length) go to `note`.
ReplayPlan PrepareReplay(const ReplayOptions& o, const std::function<void(const std::string&)>& note);

}  // namespace rths::supervisor
