#pragma once
/// @file Writing files safely when the disk fills up. Files that must be writable at the end of a
/// run even when the disk has filled up meanwhile (summary.json, each participant's outcome) have
/// their space reserved when the run starts, and the final text is written over it in place, which
/// needs no new blocks; appends to the logger's files are whole or absent (AppendWhole).
#include <cstddef>
#include <cstdint>
#include <string>

namespace rths::io {

/// Creates `path` holding `placeholder` padded with spaces to `bytes` (valid JSON if the
/// placeholder is). Returns false if it could not be written in full.
bool ReserveFile(const std::string& path, std::size_t bytes, const std::string& placeholder);

/// Writes `text` over the start of `path` (reserved or not) and cuts the file to its length.
/// Returns false on any error.
bool OverwriteFile(const std::string& path, const std::string& text);

/// Writes `size` bytes of `data` at offset `end` of `fd` (an append to a file `end` bytes long):
/// every byte, or none: on a failed or stalled write the file is cut back to `end`, so nothing of
/// a half-written event or row stays behind. Returns "" or the error naming `path`
/// ("writing PATH failed: WHY", and what went wrong cutting it back, if that failed too);
/// `*cut_back` (optional) says whether the file was cut back. Adds its pwrite and ftruncate calls
/// to `*system_calls`. Used by the logger's files (io::MappedLogFile, io::SignalsCsvWriter).
std::string AppendWhole(int fd, const std::string& path, std::int64_t end, const void* data, std::size_t size,
                        std::int64_t* system_calls, bool* cut_back = nullptr);

}  // namespace rths::io
