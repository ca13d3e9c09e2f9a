/// @file Command-line overrides (`--set KEY=VALUE`, issue 13): ApplyOverrides on the TOML text,
/// then the same parsing and checks as the file's, errors naming the --set that caused them.
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/text.h"
#include "scenario/walk.h"

namespace rths::scenario {

namespace {

/// "run.duration_s" -> {"run", "duration_s"}; quoted parts are not supported (no scenario key needs them).
std::vector<std::string> SplitDotted(const std::string& key) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : key) {
    if (c == '.') {
      parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  parts.push_back(part);
  return parts;
}

/// Rethrows a validation error about a key that --set changed with the --set argument named: the
/// error's key (after "FILE: ") is the set key, a table holding it ("foo" for --set foo.bar=1, an
/// unknown table), or a key inside it. A --set of exactly the error's key is named alone (the last
/// one: it is in force); else every --set inside the table (a sum over its keys, say).
[[noreturn]] void RethrowWithSet(const Error& e, const std::vector<std::string>& sets) {
  const std::string& where = e.where();
  const auto colon = where.rfind(": ");
  const std::string wkey = colon == std::string::npos ? where : where.substr(colon + 2);
  const auto within = [](const std::string& inner, const std::string& outer) {
    return inner == outer || (inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
                              inner[outer.size()] == '.');
  };
  std::string exact, inside;
  for (const auto& set : sets) {
    const std::string key(Trim(std::string_view(set).substr(0, set.find('=')), kTomlWhitespace));
    if (key.empty() || wkey.empty()) continue;
    if (key == wkey) exact = set;
    if (within(key, wkey) || within(wkey, key)) inside += (inside.empty() ? "--set " : ", --set ") + set;
  }
  if (!exact.empty()) throw Error(where, e.problem() + " (set by --set " + exact + ")");
  if (!inside.empty()) throw Error(where, e.problem() + " (set by " + inside + ")");
  throw e;
}

}  // namespace

std::string ApplyOverrides(std::string_view toml_text, const std::vector<std::string>& sets, const std::string& path) {
  toml::table root = detail::ParseToml(toml_text, path);
  for (const auto& set : sets) {
    const auto eq = set.find('=');
    const std::string key =
        eq == std::string::npos ? "" : std::string(Trim(std::string_view(set).substr(0, eq), kTomlWhitespace));
    if (eq == std::string::npos || key.empty()) {
      throw Error("--set " + set, "expected KEY=VALUE with a dotted scenario key, e.g. --set run.duration_s=5 "
                                  "(every key: docs/scenarios.md)");
    }
    const std::string text(Trim(std::string_view(set).substr(eq + 1), kTomlWhitespace));
    toml::table value_table;
    try {
      value_table = toml::parse("v = " + text);
    } catch (const toml::parse_error&) {
      // Not a TOML value: a bare word is a string (--set controller.kind=ff_lqg).
      value_table = toml::table{{"v", text}};
    }
    const std::vector<std::string> parts = SplitDotted(key);
    toml::table* t = &root;
    std::string walked;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (parts[i].empty()) throw Error("--set " + set, fmt::format("\"{}\": empty part in the dotted key", key));
      walked += (walked.empty() ? "" : ".") + parts[i];
      toml::node* next = t->get(parts[i]);
      if (next == nullptr) {
        t = t->insert_or_assign(parts[i], toml::table{}).first->second.as_table();
      } else if (next->is_table()) {
        t = next->as_table();
      } else {
        throw Error("--set " + set, fmt::format("{} is a value in the scenario, not a table, so {} cannot be set",
                                                walked, key));
      }
    }
    if (parts.back().empty()) throw Error("--set " + set, fmt::format("\"{}\": empty part in the dotted key", key));
    value_table.get("v")->visit([&](auto&& v) { t->insert_or_assign(parts.back(), v); });
  }
  std::ostringstream out;
  out << root << "\n";
  return out.str();
}

Scenario LoadScenario(const std::string& path, const std::vector<std::string>& sets) {
  if (sets.empty()) return LoadScenario(path);
  const std::string bytes = detail::ReadScenarioFile(path);
  const std::string text = ApplyOverrides(bytes, sets, path);
  try {
    Scenario s = ParseScenario(text, path);
    s.sha256 = Sha256Hex(text);
    return s;
  } catch (const Error& e) {
    RethrowWithSet(e, sets);
  }
}

Scenario WithOverrides(const Scenario& s, const std::vector<std::string>& sets) {
  if (sets.empty()) return s;
  const std::string text = ApplyOverrides(ToToml(s), sets, s.path);
  try {
    Scenario out = ParseScenario(text, s.path);
    out.sha256 = Sha256Hex(text);
    return out;
  } catch (const Error& e) {
    RethrowWithSet(e, sets);
  }
}

}  // namespace rths::scenario
