#pragma once
/// @file A scenario's TOML as dotted keys and their values' text, for comparing two scenarios
/// (`rths compare`) and for naming the key a mistyped option means (the tools' --set hints).
#include <string>
#include <vector>

namespace rths::scenario {

/// One key of a scenario.toml, flattened: "controller.kind" -> "'ff_lqg'" (the TOML value's text;
/// arrays and inline tables whole).
struct ScenarioKey {
  std::string key, value;
};

/// Every key of a scenario's TOML text, flattened, tables in key order (empty if it does not parse).
std::vector<ScenarioKey> FlattenScenario(const std::string& toml_text);

}  // namespace rths::scenario
