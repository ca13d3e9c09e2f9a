#pragma once
/// @file The default output folder of a command: runs/<UTC time>-<label>, never an existing one.
#include <filesystem>
#include <string>

namespace rths::io {

/// runs/<YYYYmmdd-HHMMSS UTC>-<label>, or with -2, -3, ... appended if that folder exists. Not
/// created.
std::filesystem::path NewOutputFolder(const std::string& label);

}  // namespace rths::io
