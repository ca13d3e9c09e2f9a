#pragma once
/// @file Work of N items as one Slurm job array (issue 28): what the sweep's executor
/// (sweep/slurm.h) and a study's runs on Slurm (sweep/study_on_slurm.h) share. Item i belongs to
/// array task i % T; task c runs `command --chunk c --chunks T --jobs $SLURM_CPUS_PER_TASK` on its
/// node, which makes the items of its chunk that are not done yet. Whether an item is done is read
/// from the shared filesystem (a row, a summary.json), never from Slurm: a task whose items are not
/// all done after its job has ended failed (cancelled, timed out, its node lost), whatever Slurm
/// says; the collector names it with what scontrol still knows and submits it again.
///
/// Files: DIR/slurm/task.sh (the batch script: the settings' `setup` lines, each single-quoted and
/// eval'd in order, a failing one stopping the task, then the command), DIR/slurm/task-<job>_<c>.out
/// (each task's output).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sweep/spec.h"

namespace rths::sweep {

/// The most array tasks one submission holds (Slurm's default MaxArraySize is 1001).
inline constexpr std::int64_t kMaxArrayTasks = 1000;
/// Items per array task when neither the SPEC nor a flag says.
inline constexpr std::int64_t kDefaultRunsPerTask = 25;

/// The Slurm commands, as paths (the main program finds them on PATH: `module load slurm`).
struct SlurmPrograms {
  std::string sbatch = "sbatch", squeue = "squeue", scontrol = "scontrol";
};

/// The chunk count T for `items`: ceil(items / per_task) (kDefaultRunsPerTask when 0), at most
/// kMaxArrayTasks.
std::int64_t ChunkCount(std::int64_t items, std::int64_t per_task);

/// N items as an array of T tasks.
struct ArrayWork {
  std::string name;                         ///< the job's name is "rths-<name>"
  std::filesystem::path dir;                ///< DIR: task.sh and the tasks' output go in DIR/slurm
  std::int64_t items = 0, chunks = 1;       ///< N, T
  std::vector<std::string> command;         ///< a task's program and arguments (absolute paths)
  std::function<bool(std::int64_t)> done;   ///< item i is done (its result is on the shared filesystem)
  std::string noun = "runs";                ///< what an item is, in messages
  std::string mark = "a row";               ///< what a done item has, in messages
};

/// Where a job array stands and what to say.
struct ArrayRun {
  SlurmSettings settings;                   ///< partition, time, account, cpus per task, retries, sbatch_args
  SlurmPrograms programs;
  double poll_s = 2.0;                      ///< squeue every poll_s while waiting [s]
  std::function<void(const std::string&)> say;  ///< progress and failures, a line each (optional)
};

/// The tasks with items not done.
std::vector<std::int64_t> UnfinishedTasks(const ArrayWork& w);
/// Writes DIR/slurm/task.sh (the batch script every array task runs) and returns its path.
/// Throws rths::Error if it cannot be written.
std::filesystem::path WriteTaskScript(const ArrayWork& w, const ArrayRun& r);
/// The sbatch command (program and arguments) that submits tasks `tasks` of DIR/slurm/task.sh:
/// --parsable, the job's name, --array=LIST, --cpus-per-task, --output, --chdir=DIR, then the
/// settings' partition, time, account and sbatch_args.
std::vector<std::string> SbatchCommand(const ArrayWork& w, const std::vector<std::int64_t>& tasks, const ArrayRun& r);
/// `argv` as one line a shell reads back (arguments with other than [A-Za-z0-9-_=./,:%+@]
/// single-quoted), to show a command.
std::string ShellLine(const std::vector<std::string>& argv);
/// WriteTaskScript, then runs SbatchCommand; returns the job id.
/// Throws rths::Error with sbatch's message if it refuses.
std::string SubmitArray(const ArrayWork& w, const std::vector<std::int64_t>& tasks, const ArrayRun& r);
/// Waits until job `id` has left the queue, saying how many items are done as it goes.
void WaitForJob(const ArrayWork& w, const std::string& id, const ArrayRun& r);
/// The tasks with items not done, each named with what Slurm knows of it in job `id`.
std::vector<std::int64_t> ExplainFailures(const ArrayWork& w, const std::string& id, const ArrayRun& r);

/// Waits for `jobs.back()` (if any), then submits the failed tasks again while `*retries_left` > 0,
/// appending each new job to `jobs` and calling `on_submit` (to save state) after each. Returns the
/// tasks still failing at the end.
std::vector<std::int64_t> WaitAndRetry(const ArrayWork& w, const ArrayRun& r, std::vector<std::string>* jobs,
                                       int* retries_left, const std::function<void()>& on_submit = {});

/// "0-7" or "3,5": a sorted task list as sbatch --array takes it.
std::string ArrayList(const std::vector<std::int64_t>& tasks);

}  // namespace rths::sweep
