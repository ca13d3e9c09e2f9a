#pragma once
/// @file Files of the rths checkout (a study's base scenario) found from wherever a command runs.
#include <filesystem>
#include <string>

namespace rths::io {

/// The file `rel` (e.g. "scenarios/fig9_base.toml") in the source tree: under `root` if given (the
/// checkout the user named: a tool passes its RTHS_SOURCE_DIR), else searched upwards from the
/// current folder, from the executable's folder and from this source file's compile-time location.
/// Throws rths::Error naming where it looked.
std::filesystem::path FindSourceFile(const std::string& rel, const std::filesystem::path& root = {});

}  // namespace rths::io
