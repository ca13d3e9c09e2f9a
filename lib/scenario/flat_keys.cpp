#include "scenario/flat_keys.h"

#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

namespace rths::scenario {
namespace {

/// A value's text: floats as the shortest text that reads back to the same double (0.0008, not
/// toml++'s 0.00080000000000000004), with a decimal point kept; arrays element by element; the
/// rest as toml++ writes it.
std::string ValueText(const toml::node& v) {
  if (const auto* f = v.as_floating_point()) {
    std::string t = fmt::format("{}", f->get());
    if (t.find_first_of(".eEn") == std::string::npos) t += ".0";  // 2.0, not 2 (n: inf, nan)
    return t;
  }
  if (const auto* a = v.as_array()) {
    std::string t = "[ ";
    for (std::size_t i = 0; i < a->size(); ++i) t += (i ? ", " : "") + ValueText(*a->get(i));
    return a->empty() ? "[]" : t + " ]";
  }
  std::ostringstream text;
  v.visit([&](const auto& node) { text << node; });
  return text.str();
}

void Flatten(const toml::table& t, const std::string& prefix, std::vector<ScenarioKey>* out) {
  for (auto&& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      Flatten(*sub, key, out);
      continue;
    }
    out->push_back({key, ValueText(v)});
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
