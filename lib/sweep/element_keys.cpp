#include "sweep/element_keys.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/core.h>
#include <toml++/toml.h>

#include "core/error.h"
#include "scenario/scenario.h"

namespace rths::sweep {

namespace {

/// The largest index an element key may name.
constexpr std::size_t kMaxIndex = 1'000'000;

/// The numbers of `array_key` in TOML text, as literals; nullopt where the key is absent.
std::optional<std::vector<std::string>> NumbersAt(const std::string& toml_text, const std::string& source,
                                                  const std::string& array_key) {
  const toml::table root = toml::parse(toml_text, source);
  const toml::node_view<const toml::node> node = root.at_path(array_key);
  if (!node) return std::nullopt;
  const toml::array* a = node.as_array();
  if (a == nullptr) throw Error(source + ": " + array_key, "is not an array, so it has no elements to draw");
  std::vector<std::string> out;
  for (const toml::node& e : *a) {
    if (const auto* i = e.as_integer()) {
      out.push_back(std::to_string(i->get()));
    } else if (const auto* f = e.as_floating_point(); f && std::isfinite(f->get())) {
      out.push_back(FloatLiteral(f->get()));
    } else {
      throw Error(source + ": " + array_key, fmt::format("element {} is not a finite number", out.size()));
    }
  }
  return out;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open scenario file");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string ArrayText(const std::vector<std::string>& elements) {
  std::string out = "[";
  for (std::size_t i = 0; i < elements.size(); ++i) out += (i ? ", " : "") + elements[i];
  return out + "]";
}

}  // namespace

std::optional<ElementKey> SplitElementKey(const std::string& key, const std::string& where) {
  const std::size_t open = key.find('[');
  if (open == std::string::npos && key.find(']') == std::string::npos) return std::nullopt;
  const std::string digits = open == std::string::npos ? "" : key.substr(open + 1, key.size() - open - 2);
  const bool ok = open != std::string::npos && open > 0 && key.back() == ']' && !digits.empty() &&
                  digits.size() <= 7 && digits.find_first_not_of("0123456789") == std::string::npos;
  const std::size_t index = ok ? std::stoul(digits) : 0;
  if (!ok || index > kMaxIndex) {
    throw Error(where, fmt::format("\"{}\": an element of an array is KEY[i], i an integer in [0, {}], e.g. "
                                   "\"controller.lti.feedback.num[0]\"",
                                   key, kMaxIndex));
  }
  return ElementKey{key.substr(0, open), index};
}

std::vector<std::string> ArrayIn(const std::string& scenario, const std::vector<std::string>& sets,
                                 const std::string& array_key) {
  // The file's text as --set changes it: what scenario::LoadScenario parses.
  const std::string text = scenario::ApplyOverrides(ReadFile(scenario), sets, scenario);
  if (auto numbers = NumbersAt(text, scenario, array_key)) return *numbers;
  // Not written in the file: the scenario's default, every key written out.
  const std::string all = scenario::ToToml(scenario::LoadScenario(scenario, sets));
  if (auto numbers = NumbersAt(all, scenario, array_key)) return *numbers;
  throw Error(scenario + ": " + array_key, "has no array here (absent, or the default of a key that is not an "
                                           "array): give the whole array in the case or in the SPEC's [set]");
}

std::vector<std::string> ScenarioSets(const RunPoint& p) {
  std::vector<std::string> out;
  for (const std::string& set : p.sets) {
    const std::size_t eq = set.find('=');
    const auto element = SplitElementKey(set.substr(0, eq), "--set " + set);
    if (!element) {
      out.push_back(set);
      continue;
    }
    std::vector<std::string> a = ArrayIn(p.scenario, out, element->array_key);
    if (element->index >= a.size()) {
      throw Error(p.scenario + ": " + element->array_key,
                  fmt::format("{}: index {} is out of range [0, {}) (the array is {})", set.substr(0, eq),
                              element->index, a.size(), ArrayText(a)));
    }
    a[element->index] = set.substr(eq + 1);
    out.push_back(element->array_key + "=" + ArrayText(a));
  }
  return out;
}

void CheckElementKeys(const Spec& spec) {
  std::vector<std::string> fixed;
  for (const auto& [key, value] : spec.fixed) fixed.push_back(key + "=" + value);
  for (const Draw& d : spec.draw) {
    const std::string where = fmt::format("{}: draw.\"{}\"", spec.path, d.key);
    const auto element = SplitElementKey(d.key, where);
    if (!element) continue;
    // The array's values before the draws: [set], or each level of a grid key of the same array.
    std::vector<std::vector<std::string>> variants = {fixed};
    for (const Axis& a : spec.grid) {
      if (a.key != element->array_key) continue;
      variants.clear();
      for (const std::string& level : a.values) {
        variants.push_back(fixed);
        variants.back().push_back(a.key + "=" + level);
      }
    }
    for (const std::string& c : spec.cases) {
      for (const auto& sets : variants) {
        std::vector<std::string> values;
        try {
          values = ArrayIn(c, sets, element->array_key);
        } catch (const Error& e) {
          throw Error(where, e.what());
        }
        if (element->index >= values.size()) {
          throw Error(where, fmt::format("index {} is out of range [0, {}): {} is {} in {}{}", element->index,
                                         values.size(), element->array_key, ArrayText(values),
                                         std::filesystem::path(c).filename().string(),
                                         sets.size() > fixed.size() ? " (grid " + sets.back() + ")" : ""));
        }
      }
    }
  }
}

}  // namespace rths::sweep
