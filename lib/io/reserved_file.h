#pragma once
/// @file Files that must be writable at the end of a run even when the disk has filled up
/// meanwhile (summary.json, each participant's outcome): their space is reserved when the run
/// starts and the final text is written over it in place, which needs no new blocks.
#include <cstddef>
#include <string>

namespace rths::io {

/// Creates `path` holding `placeholder` padded with spaces to `bytes` (valid JSON if the
/// placeholder is). Returns false if it could not be written in full.
bool ReserveFile(const std::string& path, std::size_t bytes, const std::string& placeholder);

/// Writes `text` over the start of `path` (reserved or not) and cuts the file to its length.
/// Returns false on any error.
bool OverwriteFile(const std::string& path, const std::string& text);

}  // namespace rths::io
