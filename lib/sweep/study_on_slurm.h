#pragma once
/// @file A study's lockstep runs as a Slurm job array (`rths reproduce NAME --executor slurm`,
/// issue 28): the same runs, in the same folders, with the same outputs byte for byte as when
/// they run here, so every reproduction (fig9's frequency x controller grid, the benchmark's cases
/// x controllers x perturbed plants, ...) runs on a cluster without a change to the study.
///
/// A batch of RunSpecs (studies::RunStudyBatch's) becomes DIR/slurm/batch-<n>.json (each run's
/// label and folder, and its scenario written to DIR/slurm/batch-<n>/<k>.toml) and one job array
/// (sweep/slurm_array.h): task c runs `rths-sweep --batch FILE --task --chunk c --chunks T --jobs J`,
/// which makes the runs k of its chunk whose folder has no summary.json yet, through
/// studies::RunBatch as the local study does. A run is done when its summary.json exists (a failed
/// run has one too). Then the study goes on with the RunResults read from those folders
/// (studies::ResultOfRunFolder). DIR (the study's --out) must be on a filesystem the compute nodes
/// share (docs/cluster.md).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "studies/batch.h"
#include "sweep/slurm_array.h"

namespace rths::sweep {

struct StudySlurmOptions {
  std::filesystem::path dir;            ///< the study's output folder (shared with the nodes)
  SlurmSettings settings;               ///< partition, time, account, runs_per_task, cpus_per_task, retries
  SlurmPrograms programs;
  std::string sweep_program;            ///< absolute path of rths-sweep, as the compute nodes see it
  double poll_s = 2.0;
  std::function<void(const std::string&)> say;
};

/// Makes `specs` as a job array and returns their results in spec order, calling `progress` after
/// each (in order, once the array is done). Throws rths::Error if sbatch refuses the array or if
/// runs are still missing after the retries (naming the tasks and their output files).
std::vector<studies::RunResult> RunSpecsOnSlurm(const std::vector<studies::RunSpec>& specs,
                                                const StudySlurmOptions& o, const studies::Progress& progress = {});

/// One array task of such a batch (`rths-sweep --batch FILE --task`): the runs k of chunk `chunk`
/// of `chunks` without a summary.json, `jobs` at a time. Returns how many it made.
std::int64_t RunBatchTask(const std::filesystem::path& batch_file, std::int64_t chunk, std::int64_t chunks, int jobs);

}  // namespace rths::sweep
