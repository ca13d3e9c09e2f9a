#pragma once
/// @file A participant group as processes (the udpm transport): each participant a child process
/// (procs/<role>, fork/exec), watched through a signalfd so that one that dies is noticed at once
/// and the others are stopped (supervisor/teardown.h).
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "participants/group.h"
#include "supervisor/request.h"
#include "supervisor/teardown.h"

namespace rths::supervisor {

/// What a process group needs beyond the plan.
struct ProcessGroupSpec {
  std::string scenario_path;              ///< the file every participant reads
  std::int64_t run_id = 0;
  std::filesystem::path out;              ///< output folder (out/logs/<role>.log and .json)
  std::filesystem::path bin_dir;          ///< where rths-<role> are
  std::string url;                        ///< the run's udpm URL
  ExternalRoles external;                 ///< not started (their outcomes: participants::ExternalOutcome)
  std::vector<std::string> role_args;     ///< extra arguments for every participant
};

/// Starts the group's processes (logger first, lockstep::kBuildOrder), waits for every one, and tears the
/// group down when one fails or on SIGINT / SIGTERM (which also set *interrupted). Returns each
/// participant's outcome (its exit status, plus what it wrote about itself in out/logs/<role>.json)
/// and, in *noticed, when a failure was noticed (unchanged if none). Throws rths::Error if a
/// program is missing or cannot be started.
std::vector<participants::Outcome> RunProcessGroup(const ProcessGroupSpec& spec,
                                                   volatile std::sig_atomic_t* interrupted,
                                                   Clock::time_point* noticed);

}  // namespace rths::supervisor
