#include "sweep/slurm_array.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>
#include <thread>

#include <fmt/core.h>

#include "core/error.h"
#include "io/command.h"
#include "io/reserved_file.h"

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

/// The SPEC's [slurm] setup as script lines, in order, before the command: each line single-quoted
/// (nothing in it can end the quoting or run into the script's own lines) and run by `eval` in the
/// script's shell, so `module load` and `export` reach the command; a line that fails stops the
/// task, naming the line and its exit code.
std::string SetupText(const std::vector<std::string>& setup) {
  if (setup.empty()) return "";
  std::string t = "# [slurm] setup of the SPEC, in order; a line that fails stops the task.\n";
  for (std::size_t k = 0; k < setup.size(); ++k) {
    const std::string line = Quote(setup[k]);
    t += fmt::format("eval {} || {{ rc=$?; echo \"rths: [slurm] setup line {} failed (exit $rc):\" {} >&2; exit 1; }}\n",
                     line, k + 1, line);
  }
  return t;
}

void Say(const ArrayRun& r, const std::string& line) {
  if (r.say) r.say(line);
}

std::vector<std::int64_t> Missing(const ArrayWork& w, std::int64_t chunk) {
  std::vector<std::int64_t> missing;
  for (std::int64_t i = chunk; i < w.items; i += w.chunks) {
    if (!w.done(i)) missing.push_back(i);
  }
  return missing;
}

std::int64_t CountDone(const ArrayWork& w) {
  std::int64_t n = 0;
  for (std::int64_t i = 0; i < w.items; ++i) n += w.done(i);
  return n;
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

/// What Slurm still knows of task `task` of job `id` ("state CANCELLED, exit 0:15, reason None"),
/// from `scontrol -o show job ID` (a line per task it remembers, for MinJobAge after the end).
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

}  // namespace

std::int64_t ChunkCount(std::int64_t items, std::int64_t per_task) {
  const std::int64_t per = per_task > 0 ? per_task : kDefaultRunsPerTask;
  return std::clamp<std::int64_t>((items + per - 1) / per, 1, kMaxArrayTasks);
}

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

std::vector<std::int64_t> UnfinishedTasks(const ArrayWork& w) {
  std::vector<std::int64_t> tasks;
  for (std::int64_t c = 0; c < w.chunks; ++c) {
    if (!Missing(w, c).empty()) tasks.push_back(c);
  }
  return tasks;
}

std::filesystem::path WriteTaskScript(const ArrayWork& w, const ArrayRun& r) {
  const fs::path slurm = w.dir / "slurm";
  fs::create_directories(slurm);
  const fs::path script = slurm / "task.sh";
  std::string command;
  for (const std::string& a : w.command) command += Quote(a) + " ";
  const std::string text = fmt::format(
      "#!/bin/bash\n"
      "# One array task of rths-{} (lib/sweep/slurm_array.h): the {} i with i % {} == $SLURM_ARRAY_TASK_ID,\n"
      "# $SLURM_CPUS_PER_TASK at a time.\n"
      "{}"
      "exec {}--chunk \"$SLURM_ARRAY_TASK_ID\" --chunks {} --jobs \"${{SLURM_CPUS_PER_TASK:-1}}\"\n",
      w.name, w.noun, w.chunks, SetupText(r.settings.setup), command, w.chunks);
  if (!io::OverwriteFile(script.string(), text)) throw Error(script.string(), "cannot write the array's batch script");
  fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec, fs::perm_options::add);
  return script;
}

std::vector<std::string> SbatchCommand(const ArrayWork& w, const std::vector<std::int64_t>& tasks, const ArrayRun& r) {
  const fs::path slurm = w.dir / "slurm";
  std::vector<std::string> argv = {r.programs.sbatch, "--parsable", "--job-name=rths-" + w.name,
                                   "--array=" + ArrayList(tasks),
                                   fmt::format("--cpus-per-task={}", r.settings.cpus_per_task),
                                   "--output=" + (slurm / "task-%A_%a.out").string(), "--chdir=" + w.dir.string()};
  if (!r.settings.partition.empty()) argv.push_back("--partition=" + r.settings.partition);
  if (!r.settings.time.empty()) argv.push_back("--time=" + r.settings.time);
  if (!r.settings.account.empty()) argv.push_back("--account=" + r.settings.account);
  for (const std::string& a : r.settings.sbatch_args) argv.push_back(a);
  argv.push_back((slurm / "task.sh").string());
  return argv;
}

std::string ShellLine(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& a : argv) {
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_=./,:%+@") == std::string::npos;
    line += (line.empty() ? "" : " ") + (plain ? a : Quote(a));
  }
  return line;
}

std::string SubmitArray(const ArrayWork& w, const std::vector<std::int64_t>& tasks, const ArrayRun& r) {
  WriteTaskScript(w, r);
  const io::CommandResult res = io::RunCommand(SbatchCommand(w, tasks, r));
  const std::string id = Trim(res.output.substr(0, res.output.find(';')));
  const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
  if (res.status != 0 || !numeric) {
    throw Error("sbatch", fmt::format("refused the job array (exit {}): {}", res.status, Trim(res.output)));
  }
  return id;
}

void WaitForJob(const ArrayWork& w, const std::string& id, const ArrayRun& r) {
  std::string last;
  for (;;) {
    const auto states = QueueStates(id, r.programs);
    std::string line = fmt::format("slurm job {}: {} done {}/{}", id, w.noun, CountDone(w), w.items);
    for (const auto& [state, n] : states) line += fmt::format(", {} {}", n, state);
    if (line != last) Say(r, line);
    last = line;
    if (states.empty()) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(r.poll_s));
  }
}

std::vector<std::int64_t> ExplainFailures(const ArrayWork& w, const std::string& id, const ArrayRun& r) {
  std::vector<std::int64_t> failed;
  for (std::int64_t c = 0; c < w.chunks; ++c) {
    const auto missing = Missing(w, c);
    if (missing.empty()) continue;
    failed.push_back(c);
    const std::int64_t in_chunk = (w.items - c + w.chunks - 1) / w.chunks;
    Say(r, fmt::format("array task {} of job {}: {} of its {} {} have no {} (first: {}); Slurm: {}; its output: {}", c,
                       id, missing.size(), in_chunk, w.noun, w.mark.substr(w.mark.find(' ') + 1), missing.front(),
                       TaskVerdict(id, c, r.programs), (w.dir / "slurm" / fmt::format("task-{}_{}.out", id, c)).string()));
  }
  return failed;
}

std::vector<std::int64_t> WaitAndRetry(const ArrayWork& w, const ArrayRun& r, std::vector<std::string>* jobs,
                                       int* retries_left, const std::function<void()>& on_submit) {
  for (;;) {
    if (jobs->empty()) return UnfinishedTasks(w);
    WaitForJob(w, jobs->back(), r);
    const auto failed = ExplainFailures(w, jobs->back(), r);
    if (failed.empty() || *retries_left <= 0) return failed;
    --*retries_left;
    jobs->push_back(SubmitArray(w, failed, r));
    if (on_submit) on_submit();
    Say(r, fmt::format("submitted array tasks {} again as job {} ({} retries left)", ArrayList(failed), jobs->back(),
                       *retries_left));
  }
}

}  // namespace rths::sweep
