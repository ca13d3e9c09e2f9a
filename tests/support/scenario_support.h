#pragma once
// Parsing scenarios in a test; links rths_scenario.
#include <string>
#include <string_view>

#include "core/error.h"
#include "scenario/scenario.h"

#include "test_support.h"

namespace rths_test {

/// The message of the rths::Error that parsing scenario `text` (named `path`) throws; "" if none.
inline std::string ParseError(std::string_view text, const std::string& path = "x.toml") {
  try {
    rths::scenario::ParseScenario(text, path);
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace rths_test
