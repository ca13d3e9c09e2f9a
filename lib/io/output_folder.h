#pragma once
/// @file Where a command may write: the default output folder of a command (runs/<UTC
/// time>-<label>, never an existing one), and the guards every command runs before writing, so
/// that no output ever replaces what a run recorded or the input being read (README "What
/// happens when things go wrong": nothing recorded is lost).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rths::io {

/// runs/<YYYYmmdd-HHMMSS UTC>-<label>, or with -2, -3, ... appended if that folder exists. Not
/// created.
std::filesystem::path NewOutputFolder(const std::string& label);

/// Checks that `dir` can take a command's output folder: it does not exist, or it is an empty
/// folder. Throws rths::Error naming `dir` ("exists and is a file, not a folder" / "output
/// folder exists and is not empty; refusing to overwrite <what> (choose another --out)").
/// Creates nothing.
void RequireNewOrEmptyFolder(const std::filesystem::path& dir, std::string_view what);

/// The files a run folder records (rths run, rths replay): log.lcm, scenario.toml, summary.json,
/// signals.csv.
const std::vector<std::string>& RecordedRunFiles();

/// Checks that writing the file `out` (given by `option`, e.g. "--csv") replaces neither one of
/// `inputs` (the same file, also through another path or a link) nor a file a run recorded (an
/// existing one of RecordedRunFiles() in a folder that holds a log.lcm: the signals.csv a
/// compact run left out may be made). Throws rths::Error naming `option` and `out`.
void RefuseToReplaceRecord(const std::filesystem::path& out, const std::vector<std::filesystem::path>& inputs,
                           std::string_view option);

}  // namespace rths::io
