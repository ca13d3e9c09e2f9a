#include "sweep/slurm.h"

#include <fstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reserved_file.h"
#include "sweep/run_sweep.h"
#include "sweep/table.h"

namespace rths::sweep {

namespace fs = std::filesystem;

namespace {

/// The state DIR/slurm/sweep.json keeps between a detached submission and its collection.
struct State {
  std::string spec;
  std::int64_t chunks = 1;
  int retries_left = 0;
  bool keep_logs = false;
  std::string sweep_program;
  SlurmSettings settings;
  std::vector<std::string> jobs;
};

fs::path StatePath(const fs::path& out) { return out / "slurm" / "sweep.json"; }

void Save(const fs::path& out, const State& s) {
  nlohmann::json j = {{"spec", s.spec},
                      {"chunks", s.chunks},
                      {"retries_left", s.retries_left},
                      {"keep_logs", s.keep_logs},
                      {"sweep_program", s.sweep_program},
                      {"partition", s.settings.partition},
                      {"time", s.settings.time},
                      {"account", s.settings.account},
                      {"cpus_per_task", s.settings.cpus_per_task},
                      {"sbatch_args", s.settings.sbatch_args},
                      {"setup", s.settings.setup},
                      {"jobs", s.jobs}};
  if (!io::OverwriteFile(StatePath(out).string(), j.dump(2) + "\n")) {
    throw Error(StatePath(out).string(), "cannot write the sweep's Slurm state");
  }
}

State Load(const fs::path& out) {
  std::ifstream in(StatePath(out));
  if (!in) throw Error(StatePath(out).string(), "cannot read: is this the folder of a sweep submitted to Slurm?");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    State s;
    s.spec = j.at("spec").get<std::string>();
    s.chunks = j.at("chunks").get<std::int64_t>();
    s.retries_left = j.at("retries_left").get<int>();
    s.keep_logs = j.at("keep_logs").get<bool>();
    s.sweep_program = j.at("sweep_program").get<std::string>();
    s.settings.partition = j.at("partition").get<std::string>();
    s.settings.time = j.at("time").get<std::string>();
    s.settings.account = j.at("account").get<std::string>();
    s.settings.cpus_per_task = j.at("cpus_per_task").get<int>();
    s.settings.sbatch_args = j.at("sbatch_args").get<std::vector<std::string>>();
    s.settings.setup = j.value("setup", std::vector<std::string>{});  // absent in sweeps submitted before [slurm] setup
    s.jobs = j.at("jobs").get<std::vector<std::string>>();
    return s;
  } catch (const std::exception& e) {
    throw Error(StatePath(out).string(), fmt::format("malformed: {}", e.what()));
  }
}

void Say(const SlurmRunOptions& o, const std::string& line) {
  if (o.say) o.say(line);
}

/// The sweep's runs as array work: item i is done when DIR/rows/<i>.json exists.
ArrayWork Work(const Spec& spec, const SlurmRunOptions& o, const State& s) {
  ArrayWork w;
  w.name = "sweep-" + spec.name;
  w.dir = o.out;
  w.items = spec.runs();
  w.chunks = s.chunks;
  w.command = {s.sweep_program, spec.path, "--out", o.out.string(), "--task"};
  if (s.keep_logs) w.command.push_back("--keep-logs");
  w.done = [out = o.out](std::int64_t i) { return fs::exists(RowFile(out, i)); };
  return w;
}

ArrayRun Runner(const SlurmRunOptions& o, const State& s) {
  return {s.settings, o.programs, o.poll_s, o.say};
}

/// Waits for the last job, submits failed tasks again while retries are left, writes the table.
SlurmOutcome Finish(const Spec& spec, State s, const SlurmRunOptions& o, SlurmOutcome outcome) {
  const ArrayWork w = Work(spec, o, s);
  const std::size_t submitted = s.jobs.size();
  outcome.failed_tasks = WaitAndRetry(w, Runner(o, s), &s.jobs, &s.retries_left, [&] { Save(o.out, s); });
  for (std::size_t j = submitted; j < s.jobs.size(); ++j) outcome.job_ids.push_back(s.jobs[j]);
  Save(o.out, s);
  WrittenTable t = WriteTable(spec, o.out);
  outcome.table = t.csv;
  outcome.rows = t.rows;
  outcome.not_completed = t.not_completed;
  outcome.absent_fields = std::move(t.absent_fields);
  return outcome;
}

}  // namespace

namespace {

/// The folders RunSweepOnSlurm makes, removed again if the first submission fails: a refused
/// sweep leaves no half-made DIR (or, in a DIR that was there, none of its own folders).
class MadeFolders {
 public:
  explicit MadeFolders(const fs::path& out) {
    for (const fs::path& p : {out, out / "rows", out / "runs", out / "slurm"}) {
      if (!fs::exists(p)) made_.push_back(p);
    }
    for (const fs::path& p : made_) fs::create_directories(p);
  }
  /// Removes what the constructor made (the outermost folder first takes the rest with it).
  void Undo() noexcept {
    std::error_code ec;
    for (const fs::path& p : made_) fs::remove_all(p, ec);
  }

 private:
  std::vector<fs::path> made_;
};

}  // namespace

SlurmOutcome RunSweepOnSlurm(const Spec& spec, const SlurmRunOptions& o) {
  if (o.sweep_program.empty() || !fs::path(o.sweep_program).is_absolute()) {
    throw Error("--executor slurm", "needs the absolute path of rths-sweep for the compute nodes");
  }
  if (!o.resume && fs::exists(o.out / "rows") && !fs::is_empty(o.out / "rows")) {
    throw Error(o.out.string(), "holds rows of an earlier attempt: add --resume to submit only the runs without "
                                "rows, or give another --out");
  }
  MadeFolders made(o.out);
  State s;
  s.spec = spec.path;
  s.chunks = ChunkCount(spec.runs(), o.settings.runs_per_task);
  s.retries_left = o.settings.retries;
  s.keep_logs = o.keep_logs;
  s.sweep_program = o.sweep_program;
  s.settings = o.settings;
  SlurmOutcome outcome;
  outcome.runs = spec.runs();
  outcome.chunks = s.chunks;
  const ArrayWork w = Work(spec, o, s);
  const std::vector<std::int64_t> todo = UnfinishedTasks(w);
  if (todo.empty()) {
    Say(o, "every run already has its row: nothing to submit");
    Save(o.out, s);
    return Finish(spec, s, o, outcome);
  }
  if (o.dry_run) {
    WriteTaskScript(w, Runner(o, s));
    outcome.dry_run_command = ShellLine(SbatchCommand(w, todo, Runner(o, s)));
    return outcome;
  }
  try {
    s.jobs.push_back(SubmitArray(w, todo, Runner(o, s)));
  } catch (...) {  // sbatch missing or refusing: nothing was submitted, so nothing of this call stays
    made.Undo();
    throw;
  }
  outcome.job_ids.push_back(s.jobs.back());
  Save(o.out, s);
  Say(o, fmt::format("submitted job {}: array tasks {} of {} ({} runs each at most, {} cpus per task)", s.jobs.back(),
                     ArrayList(todo), s.chunks, (spec.runs() + s.chunks - 1) / s.chunks, s.settings.cpus_per_task));
  if (o.detach) {
    outcome.detached = true;
    return outcome;
  }
  return Finish(spec, s, o, outcome);
}

SlurmOutcome CollectSweep(SlurmRunOptions o, int retries) {
  State s = Load(o.out);
  if (retries >= 0) s.retries_left = retries;
  const Spec spec = LoadSpec(s.spec);
  o.settings = s.settings;
  SlurmOutcome outcome;
  outcome.runs = spec.runs();
  outcome.chunks = s.chunks;
  if (s.jobs.empty()) throw Error(StatePath(o.out).string(), "no job was submitted for this sweep");
  return Finish(spec, s, o, outcome);
}

}  // namespace rths::sweep
