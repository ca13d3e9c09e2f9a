#include "sweep/study_on_slurm.h"

#include <fstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reserved_file.h"
#include "scenario/scenario.h"
#include "supervisor/scenario_file.h"

namespace rths::sweep {

namespace fs = std::filesystem;

namespace {

/// The next free batch number of DIR/slurm (a study may submit several batches, one after another).
int NextBatch(const fs::path& slurm) {
  int n = 0;
  while (fs::exists(slurm / fmt::format("batch-{}.json", n))) ++n;
  return n;
}

}  // namespace

std::vector<studies::RunResult> RunSpecsOnSlurm(const std::vector<studies::RunSpec>& specs,
                                                const StudySlurmOptions& o, const studies::Progress& progress) {
  if (specs.empty()) return {};
  if (o.sweep_program.empty() || !fs::path(o.sweep_program).is_absolute()) {
    throw Error("--executor slurm", "needs the absolute path of rths-sweep for the compute nodes");
  }
  const fs::path slurm = o.dir / "slurm";
  fs::create_directories(slurm);
  const int n = NextBatch(slurm);
  const fs::path inputs = slurm / fmt::format("batch-{}", n);
  fs::create_directories(inputs);
  nlohmann::json batch = {{"origin", "rths reproduce"}, {"runs", nlohmann::json::array()}};
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const fs::path file = inputs / fmt::format("{}.toml", k);
    supervisor::WriteScenarioFile(file, specs[k].label + " (the input of an array task)", specs[k].scenario);
    batch["runs"].push_back({{"label", specs[k].label}, {"scenario", file.string()}, {"dir", specs[k].dir.string()}});
  }
  const fs::path batch_file = slurm / fmt::format("batch-{}.json", n);
  if (!io::OverwriteFile(batch_file.string(), batch.dump(2) + "\n")) throw Error(batch_file.string(), "cannot write");

  ArrayWork w;
  w.name = fmt::format("reproduce-batch-{}", n);
  w.dir = o.dir;
  w.items = static_cast<std::int64_t>(specs.size());
  w.chunks = ChunkCount(w.items, o.settings.runs_per_task);
  w.command = {o.sweep_program, "--batch", batch_file.string(), "--task"};
  std::vector<fs::path> dirs;
  for (const auto& s : specs) dirs.push_back(s.dir);
  w.done = [dirs](std::int64_t k) { return fs::exists(dirs[static_cast<std::size_t>(k)] / "summary.json"); };
  const ArrayRun r{o.settings, o.programs, o.poll_s, o.say};
  std::vector<std::string> jobs = {SubmitArray(w, UnfinishedTasks(w), r)};
  if (o.say) {
    o.say(fmt::format("submitted job {}: {} runs in {} array tasks ({} cpus per task)", jobs.back(), w.items, w.chunks,
                      o.settings.cpus_per_task));
  }
  int retries = o.settings.retries;
  const auto failed = WaitAndRetry(w, r, &jobs, &retries);
  if (!failed.empty()) {
    throw Error("--executor slurm", fmt::format("array tasks {} of job {} left runs without a summary.json after {} "
                                                "retries (their output: {}/task-{}_<task>.out)",
                                                ArrayList(failed), jobs.back(), o.settings.retries, slurm.string(),
                                                jobs.back()));
  }
  std::vector<studies::RunResult> results;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    results.push_back(studies::ResultOfRunFolder(specs[k].dir, specs[k].label));
    if (progress) progress(k + 1, specs.size(), results.back());
  }
  return results;
}

std::int64_t RunBatchTask(const fs::path& batch_file, std::int64_t chunk, std::int64_t chunks, int jobs) {
  std::ifstream in(batch_file);
  if (!in) throw Error(batch_file.string(), "cannot read the batch");
  nlohmann::json batch;
  try {
    batch = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error(batch_file.string(), fmt::format("malformed: {}", e.what()));
  }
  if (chunks < 1 || chunk < 0 || chunk >= chunks) {
    throw Error("--chunk", fmt::format("{} of {}: needs 0 <= chunk < chunks", chunk, chunks));
  }
  const auto& runs = batch.at("runs");
  std::vector<studies::RunSpec> specs;
  for (std::int64_t k = chunk; k < static_cast<std::int64_t>(runs.size()); k += chunks) {
    const auto& run = runs[static_cast<std::size_t>(k)];
    const fs::path dir = run.at("dir").get<std::string>();
    if (fs::exists(dir / "summary.json")) continue;  // made by an earlier attempt
    std::error_code ec;  // what an interrupted attempt left (RunBatch refuses a folder with a log)
    fs::remove(dir / "log.lcm", ec);
    fs::remove(dir / "signals.csv", ec);
    specs.push_back({run.at("label").get<std::string>(), scenario::LoadScenario(run.at("scenario").get<std::string>()), dir});
  }
  studies::RunBatch(specs, std::max(1, jobs), nullptr, {}, batch.value("origin", std::string("rths reproduce")));
  return static_cast<std::int64_t>(specs.size());
}

}  // namespace rths::sweep
