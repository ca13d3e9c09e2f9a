// libFuzzer target: scenario::ParseScenario on arbitrary text (docs/fuzzing.md).
// Property: it returns a valid scenario or throws rths::Error; anything else (another exception,
// a crash, ASan/UBSan findings) is a bug. An accepted scenario must survive ToToml: parsing its
// ToToml text gives the same ToToml text back.
// File system: ParseScenario only checks that referenced files exist (stat); the scenario's
// path is in an empty temporary folder, so relative references resolve to nothing.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/error.h"
#include "scenario/scenario.h"

namespace {
char g_dir[] = "/tmp/rths-fuzz-scenario.XXXXXX";

void RemoveDir() { ::rmdir(g_dir); }  // empty: nothing is ever written into it

const std::string& ScenarioPath() {
  static const std::string path = [] {
    if (!::mkdtemp(g_dir)) std::abort();
    std::atexit(RemoveDir);
    return std::string(g_dir) + "/fuzz.toml";
  }();
  return path;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  rths::scenario::Scenario s;
  try {
    s = rths::scenario::ParseScenario(text, ScenarioPath());
  } catch (const rths::Error&) {
    return 0;  // refused with a message: fine
  }
  const std::string toml = rths::scenario::ToToml(s);
  try {
    const auto back = rths::scenario::ParseScenario(toml, ScenarioPath());
    if (rths::scenario::ToToml(back) != toml) {
      std::fprintf(stderr, "ToToml round trip changed the scenario:\n%s\n", toml.c_str());
      std::abort();
    }
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "ToToml text of an accepted scenario is refused: %s\n%s\n", e.what(), toml.c_str());
    std::abort();
  }
  return 0;
}
