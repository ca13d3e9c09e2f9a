/// @file Parsing and loading: the scenario text is parsed, checked and every file it names read,
/// once, at the edge (ParseScenario, LoadScenario); the hash is of the scenario file's bytes.
#include <openssl/evp.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "scenario/from_toml.h"
#include "scenario/walk.h"

namespace rths::scenario {

namespace detail {

toml::table ParseToml(std::string_view toml_text, const std::string& path) {
  try {
    return toml::parse(toml_text, path);
  } catch (const toml::parse_error& e) {
    const toml::source_position& at = e.source().begin;
    throw Error(fmt::format("{}:{}:{}", DisplayName(path), at.line, at.column),
                fmt::format("TOML syntax error at line {}, column {}: {}", at.line, at.column, e.description()));
  }
}

std::string ReadScenarioFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(path, "is a folder, not a scenario file (give a .toml file, e.g. scenarios/default.toml; a run "
                      "folder's scenario is RUN_DIR/scenario.toml)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open scenario file");
  std::string bytes;
  try {
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {
    throw Error(path, std::string("cannot read scenario file: ") + e.what());
  }
  if (in.bad()) throw Error(path, "cannot read scenario file");
  return bytes;
}

namespace {

/// true if a key is set somewhere in `t` (a table holding only empty tables has none).
bool AnyKey(const toml::table& t) {
  for (auto&& [key, node] : t)
    if (const toml::table* sub = node.as_table(); !sub || AnyKey(*sub)) return true;
  return false;
}

}  // namespace
}  // namespace detail

std::int64_t Scenario::steps() const { return std::llround(run.duration_s / run.dt_s); }

std::string Sha256Hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw Error("Sha256Hex", "OpenSSL EVP_Digest(sha256) failed");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0x0f];
  }
  return hex;
}

Scenario ScenarioFromToml(const toml::table& root, const std::string& path) {
  using namespace detail;
  const std::string file = DisplayName(path);
  // An empty scenario (an empty file, only comments, only table headers) is a mistake, not a
  // request for the default experiment: at least one key must be set somewhere.
  if (!AnyKey(root)) {
    throw Error(file, "empty scenario: no key is set (the text is empty or holds only comments and table headers); "
                      "set at least one key, e.g. [run] name = \"...\" (every key: docs/scenarios.md)");
  }
  Scenario s;
  s.path = path;
  Section top(file, &root, "");
  ReadFields(&top, &s);
  // A model file of `rths identify --damper` carries how its fit ended in [fit]
  // (ident/fit_status.h): a record for the reader, not part of the scenario.
  (void)top.Sub("fit");
  top.Finish();
  ValidateScenario(s);
  ReadReferencedFiles(&s);
  for (signal::SignalSpec* signal : {&s.structure.ground, &s.structure.desired}) {
    if (signal->kind == signal::SignalKind::kFile) signal->file = ResolveFile(path, signal->file).string();
  }
  if (!s.structure.file.empty()) s.structure.file = ResolveFile(path, s.structure.file).string();
  if (!s.structure.reference_file.empty())
    s.structure.reference_file = ResolveFile(path, s.structure.reference_file).string();
  if (s.marths.enabled) {  // (a scenario without [marths] keeps the defaults as written: its ToToml has none)
    for (std::string* f : {&s.marths.reference_k_file, &s.marths.reference_m_file, &s.marths.rodeac_file,
                           &s.marths.ground_file}) {
      if (!f->empty()) *f = ResolveFile(path, *f).string();
    }
  }
  return s;
}

Scenario ParseScenario(std::string_view toml_text, const std::string& path) {
  return ScenarioFromToml(detail::ParseToml(toml_text, path), path);
}

Scenario LoadScenario(const std::string& path) {
  const std::string bytes = detail::ReadScenarioFile(path);
  Scenario s = ParseScenario(bytes, path);
  s.sha256 = Sha256Hex(bytes);
  return s;
}

}  // namespace rths::scenario
