#pragma once
/// @file The scenario that runs, as a file in the run's folder: a copy of the user's file, or
/// (with `--set` overrides, or a scenario built in code) the scenario written out in full.
#include <filesystem>
#include <string>

#include "scenario/scenario.h"

namespace rths::supervisor {

/// Writes `s` in full (scenario::ToToml, file paths absolute) to `file` under the comment line
/// "# <header>" and loads it back, so the scenario's hash is the file's. The loaded scenario keeps
/// s.realtime.enabled (`--realtime` paces a run without being a key of the file). Throws
/// rths::Error naming the file.
scenario::Scenario WriteScenarioFile(const std::filesystem::path& file, const std::string& header,
                                     const scenario::Scenario& s);

}  // namespace rths::supervisor
