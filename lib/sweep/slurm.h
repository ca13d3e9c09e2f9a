#pragma once
/// @file The Slurm executor of a sweep (`rths sweep SPEC --executor slurm`, issue 28): the sweep's
/// runs as one job array, Slurm doing all the scheduling; no daemon of ours.
///
/// The runs are split into T chunks (runs_per_task each, T <= kMaxArrayTasks); array task c runs
/// the indices i with i % T == c by calling this same program on the compute node
/// (sweep/slurm_array.h, which the studies' runs on Slurm share):
///
///     rths-sweep SPEC --out DIR --task --chunk c --chunks T --jobs $SLURM_CPUS_PER_TASK
///
/// which writes DIR/rows/<i>.json as each run ends (lib/sweep/run_sweep.h) and skips rows already
/// there. DIR must therefore be on a filesystem the compute nodes share with the submitting host
/// (docs/cluster.md). The rows are the only record of what is done: a task that was cancelled,
/// timed out or lost its node leaves rows missing; the collector finds them, names the task with
/// what Slurm says of it (scontrol: state, exit code) and its output file, and submits those
/// tasks again (`retries` times). The table is written once every task has ended.
///
/// Files: DIR/slurm/task.sh (the array's batch script), DIR/slurm/task-<job>_<c>.out (each task's
/// output), DIR/slurm/sweep.json (the SPEC's path, T, the jobs submitted, retries left, the
/// settings with their setup lines: what
/// `rths sweep --collect DIR` needs after `--detach`).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sweep/slurm_array.h"
#include "sweep/spec.h"

namespace rths::sweep {

struct SlurmRunOptions {
  std::filesystem::path out;           ///< DIR, shared with the compute nodes (created)
  SlurmSettings settings;              ///< the SPEC's [slurm], flags applied
  std::string sweep_program;           ///< absolute path of rths-sweep, as the compute nodes see it
  SlurmPrograms programs;
  bool keep_logs = false;              ///< passed to the tasks
  bool resume = false;                 ///< DIR may hold rows already (else it must have none)
  bool detach = false;                 ///< submit, write sweep.json and return
  /// Write DIR/slurm/task.sh and say the sbatch command, submitting nothing (sbatch need not exist)
  bool dry_run = false;
  double poll_s = 2.0;                 ///< squeue every poll_s while waiting [s]
  std::function<void(const std::string&)> say;  ///< progress and failures, a line each (optional)
};

struct SlurmOutcome {
  std::int64_t runs = 0;               ///< the sweep's runs
  std::int64_t rows = 0;               ///< rows present at the end
  std::int64_t not_completed = 0;      ///< rows whose status is not "completed"
  std::int64_t chunks = 0;             ///< T
  std::vector<std::int64_t> failed_tasks;  ///< array tasks whose runs still lack rows
  std::vector<std::string> job_ids;    ///< every submission of this call, in order
  std::vector<std::string> absent_fields;  ///< recorded fields no completed row has (AbsentFields)
  bool detached = false;
  std::string dry_run_command;         ///< dry run: the sbatch command as a shell line (else empty)
  std::filesystem::path table;         ///< DIR/table.csv (not written when detached)
};

/// Submits the array tasks whose runs have no row in DIR/rows yet (every task of a new DIR; only
/// the unfinished ones of a resumed one), then, unless detached, waits, submits failed tasks
/// again up to settings.retries times and writes the table. Throws rths::Error if sbatch refuses
/// the job (with its message) or DIR cannot be written; when the first submission fails, the
/// folders this call made (DIR itself, or rows/, runs/, slurm/ in a DIR that was there) are removed.
/// With o.dry_run: writes DIR/slurm/task.sh only and returns the sbatch command it would run
/// (dry_run_command); no sweep.json, so a later real submission starts afresh.
SlurmOutcome RunSweepOnSlurm(const Spec& spec, const SlurmRunOptions& o);

/// `rths sweep --collect DIR`: for a sweep submitted with --detach, waits for its last job,
/// submits failed tasks again (the retries sweep.json has left, or `retries` if >= 0) and writes
/// the table. o.out is DIR; o.settings is taken from sweep.json.
SlurmOutcome CollectSweep(SlurmRunOptions o, int retries = -1);

}  // namespace rths::sweep
