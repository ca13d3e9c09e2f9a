#pragma once
/// @file Internal to lib/scenario: what its files share. The schema (fields.h) is walked by three
/// visitors, each in its own file: reader.cpp (TOML -> structs), writer.cpp (ToToml) and
/// checker.cpp (ranges); validate.cpp checks across keys, load.cpp parses and loads, and
/// referenced_files.cpp reads every file a scenario names, once, at the edge.
#include <filesystem>
#include <string>
#include <string_view>

#include <toml++/toml.h>

#include "scenario/ranges.h"
#include "scenario/scenario.h"
#include "scenario/toml_section.h"

namespace rths::scenario::detail {

/// Reads every table of the schema from `top` into `s` (keys and types; unknown keys are refused by
/// the caller's top.Finish()). Throws rths::Error naming the file and key.
void ReadFields(Section* top, Scenario* s);
/// The per-key ranges of [run] (every other range depends on run.dt_s and run.duration_s).
void CheckRunRanges(const Check& check, const Scenario& s);
/// The per-key ranges of every table.
void CheckRanges(const Check& check, const Scenario& s);
/// Where a file a scenario names points: relative paths are relative to the scenario's folder;
/// absolute and normalised.
std::filesystem::path ResolveFile(const std::string& scenario_path, const std::string& file);
/// TOML text parsed; a syntax error is an rths::Error naming "<file>:<line>:<column>".
toml::table ParseToml(std::string_view toml_text, const std::string& path);
/// The bytes of a scenario file. Throws rths::Error naming `path` if it is a folder or cannot be read.
std::string ReadScenarioFile(const std::string& path);

}  // namespace rths::scenario::detail
