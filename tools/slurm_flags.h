#pragma once
// The Slurm flags of `rths sweep --executor slurm` and `rths reproduce --executor slurm`, and the
// programs they run, found here at the edge (PATH, /proc/self/exe) for lib/sweep.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "core/error.h"
#include "sweep/slurm_array.h"

namespace rths::tools {

/// The flags; unset ones (empty, -1) leave the settings they are applied to as they are.
struct SlurmFlags {
  std::string partition, time, account;
  std::vector<std::string> setup;  ///< --setup LINE (repeated): replaces the SPEC's [slurm] setup
  std::int64_t runs_per_task = -1;
  int cpus_per_task = -1, retries = -1;
  double poll_s = 2.0;  ///< seconds between squeue calls while waiting

  void Add(CLI::App& app) {
    app.add_option("--partition", partition, "slurm: sbatch --partition");
    app.add_option("--time", time, "slurm: time limit per array task, e.g. 00:30:00");
    app.add_option("--account", account, "slurm: sbatch --account");
    app.add_option("--runs-per-task", runs_per_task, "slurm: runs per array task (default 25, at most 1000 tasks)")
        ->check(CLI::Range(std::int64_t{1}, rths::sweep::kMaxRuns));
    app.add_option("--cpus-per-task", cpus_per_task, "slurm: cores per array task (its runs at a time)")
        ->check(CLI::Range(1, 4096));
    app.add_option("--retries", retries, "slurm: times a task that left runs undone is submitted again (default 1)")
        ->check(CLI::Range(0, 100));
    app.add_option("--setup", setup, "slurm: a shell line the job script runs before rths, e.g. 'module load gcc/12' "
                                     "(repeat for more, in order; replaces the SPEC's [slurm] setup)")
        ->allow_extra_args(false)  // one line per --setup: a SPEC after it stays the SPEC
        ->check([](const std::string& line) { return rths::sweep::SetupLineProblem(line); });
    app.add_option("--poll-s", poll_s, "slurm: seconds between squeue calls while waiting")->check(CLI::Range(0.05, 600.0));
  }

  /// `settings` (a SPEC's [slurm], or the defaults) with the flags given applied.
  rths::sweep::SlurmSettings Applied(rths::sweep::SlurmSettings settings) const {
    if (!partition.empty()) settings.partition = partition;
    if (!time.empty()) settings.time = time;
    if (!account.empty()) settings.account = account;
    if (runs_per_task > 0) settings.runs_per_task = runs_per_task;
    if (cpus_per_task > 0) settings.cpus_per_task = cpus_per_task;
    if (retries >= 0) settings.retries = retries;
    if (!setup.empty()) settings.setup = setup;
    return settings;
  }
};

/// sbatch, squeue and scontrol as found on PATH (`module load slurm`).
inline rths::sweep::SlurmPrograms SlurmProgramsOnPath() {
  return {ProgramOnPath("sbatch"), ProgramOnPath("squeue"), ProgramOnPath("scontrol")};
}

/// The rths-sweep beside this program (the array tasks run it), as an absolute path.
inline std::string SweepProgram() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw rths::Error("--executor slurm", "cannot find this program's path (/proc/self/exe)");
  return (self.parent_path() / "rths-sweep").string();
}

}  // namespace rths::tools
