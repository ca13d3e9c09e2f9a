#pragma once
/// @file Running another program and reading what it printed (gnuplot for the figures; sbatch,
/// squeue, scontrol and scancel for a sweep on Slurm). No shell: the arguments go to execv as
/// they are, so nothing in them is interpreted.
#include <filesystem>
#include <string>
#include <vector>

namespace rths::io {

/// What a program did.
struct CommandResult {
  int status = 0;       ///< its exit code; 128 + N if killed by signal N; 127 if it could not start
  std::string output;   ///< everything it wrote to stdout and stderr, interleaved
};

/// Runs argv[0] (a path; see io::FindProgram) with the arguments argv[1..] in `dir` (empty: the
/// caller's folder), stdin from /dev/null, and waits for it. Throws rths::Error only if it cannot
/// fork (argv empty, no pipe, no process).
CommandResult RunCommand(const std::vector<std::string>& argv, const std::filesystem::path& dir = {});

/// The path of `program`: itself if it holds a '/' and is executable, else the first executable
/// file of that name in /usr/local/bin, /usr/bin, /bin, /usr/sbin (the system's own folders; a
/// main program that honours PATH passes a path, tools/cli.h ProgramOnPath); "" if none.
std::string FindProgram(const std::string& program);

}  // namespace rths::io
