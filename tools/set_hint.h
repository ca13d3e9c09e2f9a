#pragma once
// "Did you mean --set ...?": after a usage error of a command that takes `--set KEY=VALUE` (run,
// design, reproduce), an argument `--NAME` that is no option of the command but the last part of a
// scenario key ("--duration 5") gets the --set line it may mean.
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/closest_name.h"
#include "scenario/flat_keys.h"
#include "scenario/scenario.h"

namespace rths::tools {

/// Prints `rths <command>: --NAME is not an option; a scenario key? --set KEY=VALUE` for each such
/// argument of argv.
inline void PrintSetHints(CLI::App& app, int argc, char** argv, const std::string& command) {
  std::vector<scenario::ScenarioKey> keys;
  try {
    keys = scenario::FlattenScenario(scenario::ToToml(scenario::Scenario{}));
  } catch (const std::exception&) {
    return;
  }
  std::vector<std::string> leaves;
  for (const auto& k : keys) leaves.push_back(k.key.substr(k.key.rfind('.') + 1));
  std::vector<std::string_view> names(leaves.begin(), leaves.end());
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0 || arg.size() < 3) continue;
    std::string value = i + 1 < argc && argv[i + 1][0] != '-' ? argv[i + 1] : "VALUE";
    if (const auto eq = arg.find('='); eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
    }
    if (app.get_option_no_throw(arg) != nullptr) continue;
    std::string name = arg.substr(2);
    for (char& c : name) c = c == '-' ? '_' : c;
    const std::string_view close = ClosestName(name, names);
    if (close.empty()) continue;
    for (std::size_t n = 0; n < leaves.size(); ++n) {
      if (leaves[n] != close) continue;
      std::fprintf(stderr, "rths %s: %s is not an option; to change the scenario's %s: --set %s=%s\n", command.c_str(),
                   arg.c_str(), keys[n].key.c_str(), keys[n].key.c_str(), value.c_str());
      break;
    }
  }
}

}  // namespace rths::tools
