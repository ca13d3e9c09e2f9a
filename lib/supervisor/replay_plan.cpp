// A replay's pre-run check (supervisor/replay_plan.h).
#include "supervisor/replay_plan.h"

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"
#include "io/output_folder.h"
#include "participants/replay.h"

namespace rths::supervisor {

namespace fs = std::filesystem;

std::vector<std::string> LiveRoles(const std::string& arg) {
  std::vector<std::string> live;
  std::stringstream ss(arg);
  for (std::string role; std::getline(ss, role, ',');) {
    if (role.empty()) continue;
    if (role == "logger") {
      throw Error("--live", "logger: the replay always runs its own logger (it records the replay); name "
                            "integrator, controller, plant or semiactive");
    }
    participants::AnswerChannelOf(role);  // throws naming the allowed roles
    if (std::find(live.begin(), live.end(), role) == live.end()) live.push_back(role);
  }
  if (live.empty()) throw Error("--live", "name at least one of integrator, controller, plant, semiactive");
  return live;
}

namespace {

io::RunLog ReadRecord(const std::string& run_dir, const std::function<void(const std::string&)>& note) {
  const fs::path log_path = io::RunFolderLog(run_dir);  // names the folder to give
  io::RunLog record = io::ReadRunLog(log_path.string());
  const std::int64_t complete = record.CompleteSteps();
  if (complete == 0) throw Error(log_path.string(), "holds no complete step: nothing to replay");
  if (!record.Complete()) {
    note(fmt::format("{}: {}; replaying its {} complete steps", log_path.string(), record.TruncationReason(),
                     complete));
  }
  return record;
}

/// The live participants' scenario, at the recording's step.
scenario::Scenario LoadReplayScenario(const ReplayOptions& o, const std::string& path, const io::RunLog& record) {
  scenario::Scenario s;
  try {
    s = scenario::LoadScenario(path);
  } catch (const Error& e) {
    throw Error(path, fmt::format("{}{}", e.what(),
                                  o.scenario.empty() ? " (if the recorded scenario names files by a relative "
                                                       "path, give the original with --scenario)"
                                                     : ""));
  }
  if (const double dt_log = record.StepS(); dt_log > 0.0 && s.run.dt_s != dt_log) {
    throw Error(path, fmt::format("run.dt_s = {} s, but the recording ran at {} s: a replay compares "
                                  "step by step, so the step must be the recording's",
                                  s.run.dt_s, dt_log));
  }
  return s;
}

/// The steps to replay: every complete step of both, or the first --steps.
std::int64_t StepsToReplay(const ReplayOptions& o, const scenario::Scenario& s, std::int64_t complete,
                           const std::function<void(const std::string&)>& note) {
  std::int64_t steps = std::min(complete, s.steps());
  if (o.steps > 0) {
    if (o.steps > steps) {
      throw Error("--steps", fmt::format("{} is out of range [1, {}] (the complete steps of the log and the "
                                         "scenario's)",
                                         o.steps, steps));
    }
    return o.steps;
  }
  if (s.steps() != complete) {
    note(fmt::format("the scenario has {} steps, the log {}: replaying {}", s.steps(), complete, steps));
  }
  return steps;
}

}  // namespace

ReplayPlan PrepareReplay(const ReplayOptions& o, const std::function<void(const std::string&)>& note) {
  ReplayPlan r;
  r.live = LiveRoles(o.live);
  r.record = ReadRecord(o.run_dir, note);
  r.scenario_path = o.scenario.empty() ? (fs::path(o.run_dir) / "scenario.toml").string() : o.scenario;
  r.scenario = LoadReplayScenario(o, r.scenario_path, r.record);
  r.recorded_sha = r.record.ScenarioSha256();
  r.steps = StepsToReplay(o, r.scenario, r.record.CompleteSteps(), note);
  r.out = o.out.empty() ? io::NewOutputFolder("replay-" + r.scenario.run.name) : fs::path(o.out);
  io::RequireNewOrEmptyFolder(r.out, "a previous replay or run");
  return r;
}

}  // namespace rths::supervisor
