#pragma once
/// @file A scenario from TOML already parsed: for a caller that also reads the table itself (a
/// model file, diagnosis::LoadModel), so that the text is parsed once.
#include <string>

#include <toml++/toml.h>

#include "scenario/scenario.h"

namespace rths::scenario {

/// ParseScenario of the text `root` was parsed from (every check, the referenced files read, their
/// paths made absolute); `path` names it in messages and resolves relative files. No hash (sha256
/// stays ""). Throws rths::Error.
Scenario ScenarioFromToml(const toml::table& root, const std::string& path);

}  // namespace rths::scenario
