#include "sweep/slurm.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/command.h"
#include "io/reserved_file.h"
#include "sweep/run_sweep.h"
#include "sweep/table.h"

namespace rths::sweep {

namespace fs = std::filesystem;

namespace {

/// A word for bash, single-quoted.
std::string Quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

void Say(const SlurmRunOptions& o, const std::string& line) {
  if (o.say) o.say(line);
}

/// "0-7" or "3,5": the array list of `tasks` (sorted).
std::string ArrayList(const std::vector<std::int64_t>& tasks) {
  std::string list;
  for (std::size_t i = 0; i < tasks.size();) {
    std::size_t j = i;
    while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
    list += (list.empty() ? "" : ",") + (j == i ? std::to_string(tasks[i]) : fmt::format("{}-{}", tasks[i], tasks[j]));
    i = j + 1;
  }
  return list;
}

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
    s.jobs = j.at("jobs").get<std::vector<std::string>>();
    return s;
  } catch (const std::exception& e) {
    throw Error(StatePath(out).string(), fmt::format("malformed: {}", e.what()));
  }
}

/// DIR/slurm/task.sh: one array task runs its chunk through rths-sweep.
fs::path WriteTaskScript(const Spec& spec, const fs::path& out, const State& s) {
  const fs::path script = out / "slurm" / "task.sh";
  std::string text = fmt::format(
      "#!/bin/bash\n"
      "# One array task of the sweep \"{}\" (made by `rths sweep --executor slurm`; lib/sweep/slurm.h):\n"
      "# the runs i with i % {} == $SLURM_ARRAY_TASK_ID, $SLURM_CPUS_PER_TASK at a time, a row each in rows/.\n"
      "exec {} {} --out {} --task --chunk \"$SLURM_ARRAY_TASK_ID\" --chunks {} --jobs \"${{SLURM_CPUS_PER_TASK:-1}}\"{}\n",
      spec.name, s.chunks, Quote(s.sweep_program), Quote(spec.path), Quote(out.string()), s.chunks,
      s.keep_logs ? " --keep-logs" : "");
  if (!io::OverwriteFile(script.string(), text)) throw Error(script.string(), "cannot write the array's batch script");
  fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec, fs::perm_options::add);
  return script;
}

/// sbatch --array=LIST; returns the job id.
std::string Submit(const Spec& spec, const fs::path& out, const State& s, const std::vector<std::int64_t>& tasks,
                   const SlurmPrograms& programs) {
  const fs::path script = WriteTaskScript(spec, out, s);
  std::vector<std::string> argv = {programs.sbatch, "--parsable", "--job-name=rths-sweep-" + spec.name,
                                   "--array=" + ArrayList(tasks),
                                   fmt::format("--cpus-per-task={}", s.settings.cpus_per_task),
                                   "--output=" + (out / "slurm" / "task-%A_%a.out").string(),
                                   "--chdir=" + out.string()};
  if (!s.settings.partition.empty()) argv.push_back("--partition=" + s.settings.partition);
  if (!s.settings.time.empty()) argv.push_back("--time=" + s.settings.time);
  if (!s.settings.account.empty()) argv.push_back("--account=" + s.settings.account);
  for (const std::string& a : s.settings.sbatch_args) argv.push_back(a);
  argv.push_back(script.string());
  const io::CommandResult r = io::RunCommand(argv);
  const std::string id = Trim(r.output.substr(0, r.output.find(';')));
  const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
  if (r.status != 0 || !numeric) {
    throw Error("sbatch", fmt::format("refused the sweep's job array (exit {}): {}", r.status, Trim(r.output)));
  }
  return id;
}

/// Task states of job `id` as squeue lists them (-r: one line per array task); empty once every
/// task has left the queue. Throws after repeated squeue failures other than "invalid job id".
std::map<std::string, int> QueueStates(const std::string& id, const SlurmPrograms& programs) {
  for (int attempt = 0;; ++attempt) {
    const io::CommandResult r = io::RunCommand({programs.squeue, "-h", "-r", "-j", id, "-o", "%T"});
    std::map<std::string, int> states;
    if (r.status == 0) {
      std::istringstream in(r.output);
      for (std::string line; std::getline(in, line);) {
        if (!Trim(line).empty()) ++states[Trim(line)];
      }
      return states;
    }
    if (r.output.find("Invalid job id") != std::string::npos) return states;  // gone from the controller
    if (attempt >= 10) throw Error("squeue", fmt::format("fails (exit {}): {}", r.status, Trim(r.output)));
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

std::int64_t CountRows(const fs::path& out) {
  std::int64_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "rows", ec)) n += e.path().extension() == ".json";
  return n;
}

void Wait(const std::string& id, std::int64_t runs, const SlurmRunOptions& o) {
  std::string last;
  for (;;) {
    const auto states = QueueStates(id, o.programs);
    std::string line = fmt::format("slurm job {}: rows {}/{}", id, CountRows(o.out), runs);
    for (const auto& [state, n] : states) line += fmt::format(", {} {}", n, state);
    if (line != last) Say(o, line);
    last = line;
    if (states.empty()) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(o.poll_s));
  }
}

/// What Slurm still knows of task `task` of job `id` ("state CANCELLED, exit 0:15"), from
/// `scontrol -o show job ID` (a line per task it remembers, for MinJobAge after the end).
std::string TaskVerdict(const std::string& id, std::int64_t task, const SlurmPrograms& programs) {
  const io::CommandResult r = io::RunCommand({programs.scontrol, "-o", "show", "job", id});
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    const std::string padded = " " + line + " ";
    if (padded.find(fmt::format(" ArrayTaskId={} ", task)) == std::string::npos) continue;
    auto field = [&](const std::string& name) {
      const std::size_t at = padded.find(" " + name + "=");
      if (at == std::string::npos) return std::string("?");
      const std::size_t from = at + name.size() + 2;
      return padded.substr(from, padded.find(' ', from) - from);
    };
    return fmt::format("state {}, exit {}, reason {}", field("JobState"), field("ExitCode"), field("Reason"));
  }
  return "no record of it (cancelled before it started, or forgotten after MinJobAge)";
}

/// The chunks whose runs still lack rows; says why for each when `id` is its last job.
std::vector<std::int64_t> FailedTasks(const Spec& spec, const State& s, const SlurmRunOptions& o, bool explain) {
  std::vector<std::int64_t> failed;
  for (std::int64_t c = 0; c < s.chunks; ++c) {
    const auto missing = MissingRows(spec, o.out, c, s.chunks);
    if (missing.empty()) continue;
    failed.push_back(c);
    if (!explain || s.jobs.empty()) continue;
    const std::string id = s.jobs.back();
    const std::string verdict = TaskVerdict(id, c, o.programs);
    const std::int64_t in_chunk = (spec.runs() - c + s.chunks - 1) / s.chunks;
    Say(o, fmt::format("array task {} of job {}: {} of its {} runs have no row (first: run {}){}; its output: {}", c, id,
                       missing.size(), in_chunk, missing.front(), verdict.empty() ? "" : "; Slurm: " + verdict,
                       (o.out / "slurm" / fmt::format("task-{}_{}.out", id, c)).string()));
  }
  return failed;
}

/// Waits for the last job, submits failed tasks again while retries are left, writes the table.
SlurmOutcome Finish(const Spec& spec, State s, const SlurmRunOptions& o, SlurmOutcome outcome) {
  for (;;) {
    if (!s.jobs.empty()) Wait(s.jobs.back(), spec.runs(), o);
    outcome.failed_tasks = FailedTasks(spec, s, o, true);
    if (outcome.failed_tasks.empty() || s.retries_left <= 0) break;
    --s.retries_left;
    s.jobs.push_back(Submit(spec, o.out, s, outcome.failed_tasks, o.programs));
    outcome.job_ids.push_back(s.jobs.back());
    Save(o.out, s);
    Say(o, fmt::format("submitted array tasks {} again as job {} ({} retries left)", ArrayList(outcome.failed_tasks),
                       s.jobs.back(), s.retries_left));
  }
  Save(o.out, s);
  outcome.table = WriteTable(spec, o.out);
  const Table table = ReadTable(spec, o.out);
  outcome.rows = static_cast<std::int64_t>(table.rows.size());
  for (const auto& row : table.rows) outcome.not_completed += row[1] != "completed";
  outcome.absent_fields = AbsentFields(spec, table);
  return outcome;
}

}  // namespace

std::int64_t ChunkCount(std::int64_t runs, std::int64_t runs_per_task) {
  const std::int64_t per = runs_per_task > 0 ? runs_per_task : kDefaultRunsPerTask;
  return std::clamp<std::int64_t>((runs + per - 1) / per, 1, kMaxArrayTasks);
}

SlurmOutcome RunSweepOnSlurm(const Spec& spec, const SlurmRunOptions& o) {
  if (o.sweep_program.empty() || !fs::path(o.sweep_program).is_absolute()) {
    throw Error("--executor slurm", "needs the absolute path of rths-sweep for the compute nodes");
  }
  fs::create_directories(o.out / "rows");
  fs::create_directories(o.out / "runs");
  fs::create_directories(o.out / "slurm");
  if (!o.resume && CountRows(o.out) > 0) {
    throw Error(o.out.string(), "holds rows of an earlier attempt: add --resume to submit only the runs without "
                                "rows, or give another --out");
  }
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
  std::vector<std::int64_t> todo;
  for (std::int64_t c = 0; c < s.chunks; ++c) {
    if (!MissingRows(spec, o.out, c, s.chunks).empty()) todo.push_back(c);
  }
  if (todo.empty()) {
    Say(o, "every run already has its row: nothing to submit");
    Save(o.out, s);
    return Finish(spec, s, o, outcome);
  }
  s.jobs.push_back(Submit(spec, o.out, s, todo, o.programs));
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
