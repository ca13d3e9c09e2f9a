#include "scenario/flat_keys.h"

#include <sstream>

#include <toml++/toml.h>

namespace rths::scenario {
namespace {

void Flatten(const toml::table& t, const std::string& prefix, std::vector<ScenarioKey>* out) {
  for (auto&& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      Flatten(*sub, key, out);
      continue;
    }
    std::ostringstream text;
    v.visit([&](const auto& node) { text << node; });
    out->push_back({key, text.str()});
  }
}

}  // namespace

std::vector<ScenarioKey> FlattenScenario(const std::string& toml_text) {
  std::vector<ScenarioKey> out;
  try {
    Flatten(toml::parse(toml_text), "", &out);
  } catch (const toml::parse_error&) {
    out.clear();
  }
  return out;
}

}  // namespace rths::scenario
