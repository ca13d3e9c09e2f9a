// rths-replay: replay a recorded run into live participants and compare (docs/replay.md).
//
//   rths replay RUN_DIR --live ROLE[,ROLE...] [--out DIR] [--scenario FILE] [--steps N]
//
// The roles named live are built from the scenario (RUN_DIR/scenario.toml unless --scenario);
// the others answer each step with their recorded messages, in lockstep (participants/replay.h),
// run by the supervisor (supervisor/run.h). Then every live role's output channel is compared with
// the recording (supervisor/replay_report.h): identical, or the first differing step and the RMS
// and peak difference per field. Writes DIR/log.lcm, signals.csv, scenario.toml and replay.json.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli.h"
#include "external_block.h"
#include "core/error.h"
#include "io/output_folder.h"
#include "io/run_log.h"
#include "core/exit_code.h"
#include "participants/replay.h"
#include "scenario/scenario.h"
#include "supervisor/replay_report.h"
#include "supervisor/run.h"

namespace fs = std::filesystem;
namespace sup = rths::supervisor;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

struct Options {
  std::string run_dir, live, out, scenario, external, url;
  std::int64_t steps = 0;
  double join_timeout_s = 120.0;
};

/// What the replay will be, checked before anything runs.
struct Replay {
  std::vector<std::string> live;
  rths::io::RunLog record;
  std::string scenario_path;
  rths::scenario::Scenario s;
  fs::path out;
  std::int64_t steps = 0;
  std::string recorded_sha;  ///< the scenario hash the recorded participants announced ("" if none)
};

void AddOptions(CLI::App& app, Options* o) {
  app.add_option("run_dir", o->run_dir, "recorded run folder (with log.lcm and scenario.toml)")->required();
  app.add_option("--live", o->live, "ROLE[,ROLE...]: the participants to run live: integrator, controller, plant, "
                                    "semiactive (the logger always is)")
      ->required();
  app.add_option("--out", o->out, "output folder (default: runs/<time>-replay-<name>)");
  app.add_option("--scenario", o->scenario,
                 "scenario for the live participants (default: RUN_DIR/scenario.toml); change a parameter "
                 "here to see what it changes");
  app.add_option("--steps", o->steps, "replay only the first N steps (default: every complete step)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  app.add_option("--external", o->external,
                 "ROLE[,ROLE...]: live roles the user runs (controller, plant, semiactive; also named by --live): "
                 "the replay waits for them on udpm, bridged to the rest in this process (docs/replay.md)");
  app.add_option("--join-timeout-s", o->join_timeout_s,
                 "with --external: how long to wait for the external participants to say HELLO [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--lcm-url", o->url, "with --external: the udpm URL (default: udpm://239.255.76.67:<a free port>?ttl=0)");
  app.footer("Exit codes: 0 the live outputs are identical to the recording; 1 they differ (first differing step, "
             "RMS and peak per field); 2 bad input (nothing ran); 3-7 the replay run failed (as rths run).");
}

std::vector<std::string> LiveRoles(const std::string& arg) {
  std::vector<std::string> live;
  std::stringstream ss(arg);
  for (std::string role; std::getline(ss, role, ',');) {
    if (role.empty()) continue;
    if (role == "logger") {
      throw rths::Error("--live", "logger: the replay always runs its own logger (it records the replay); name "
                                  "integrator, controller, plant or semiactive");
    }
    rths::participants::AnswerChannelOf(role);  // throws naming the allowed roles
    if (std::find(live.begin(), live.end(), role) == live.end()) live.push_back(role);
  }
  if (live.empty()) throw rths::Error("--live", "name at least one of integrator, controller, plant, semiactive");
  return live;
}

rths::io::RunLog ReadRecord(const std::string& run_dir) {
  const fs::path log_path = rths::io::RunFolderLog(run_dir);  // names the folder to give
  rths::io::RunLog record = rths::io::ReadRunLog(log_path.string());
  const std::int64_t complete = record.CompleteSteps();
  if (complete == 0) throw rths::Error(log_path.string(), "holds no complete step: nothing to replay");
  if (!record.Complete()) {
    std::fprintf(stderr, "rths replay: note: %s: %s; replaying its %lld complete steps\n", log_path.c_str(),
                 record.TruncationReason().c_str(), static_cast<long long>(complete));
  }
  return record;
}

/// The live participants' scenario, at the recording's step.
rths::scenario::Scenario LoadReplayScenario(const Options& o, const std::string& path, const rths::io::RunLog& record) {
  rths::scenario::Scenario s;
  try {
    s = rths::scenario::LoadScenario(path);
  } catch (const rths::Error& e) {
    throw rths::Error(path, fmt::format("{}{}", e.what(),
                                        o.scenario.empty() ? " (if the recorded scenario names files by a relative "
                                                             "path, give the original with --scenario)"
                                                           : ""));
  }
  if (const double dt_log = record.StepS(); dt_log > 0.0 && s.run.dt_s != dt_log) {
    throw rths::Error(path, fmt::format("run.dt_s = {} s, but the recording ran at {} s: a replay compares "
                                        "step by step, so the step must be the recording's",
                                        s.run.dt_s, dt_log));
  }
  return s;
}

/// The steps to replay: every complete step of both, or the first --steps.
std::int64_t StepsToReplay(const Options& o, const rths::scenario::Scenario& s, std::int64_t complete) {
  std::int64_t steps = std::min(complete, s.steps());
  if (o.steps > 0) {
    if (o.steps > steps) {
      throw rths::Error("--steps", fmt::format("{} is out of range [1, {}] (the complete steps of the log and the "
                                               "scenario's)",
                                               o.steps, steps));
    }
    return o.steps;
  }
  if (s.steps() != complete) {
    std::fprintf(stderr, "rths replay: note: the scenario has %lld steps, the log %lld: replaying %lld\n",
                 static_cast<long long>(s.steps()), static_cast<long long>(complete), static_cast<long long>(steps));
  }
  return steps;
}

/// The scenario hash the recorded participants announced ("" if the log has no handshake).
std::string RecordedSha(const rths::io::RunLog& log) {
  for (const auto& h : log.handshakes) {
    if (!h.scenario_sha256.empty()) return h.scenario_sha256;
  }
  return "";
}

Replay Prepare(const Options& o) {
  Replay r;
  r.live = LiveRoles(o.live);
  r.record = ReadRecord(o.run_dir);
  r.scenario_path = o.scenario.empty() ? (fs::path(o.run_dir) / "scenario.toml").string() : o.scenario;
  r.s = LoadReplayScenario(o, r.scenario_path, r.record);
  r.recorded_sha = RecordedSha(r.record);
  r.steps = StepsToReplay(o, r.s, r.record.CompleteSteps());
  r.out = o.out.empty() ? rths::io::NewOutputFolder("replay-" + r.s.run.name) : fs::path(o.out);
  rths::io::RequireNewOrEmptyFolder(r.out, "a previous replay or run");
  return r;
}

void PrintHeader(const Options& o, const Replay& r) {
  std::string roles;
  for (const auto& role : r.live) roles += (roles.empty() ? "" : ",") + role;
  std::printf("rths replay: %s, %lld steps, live: %s (the others from the record)\n", o.run_dir.c_str(),
              static_cast<long long>(r.steps), roles.c_str());
  if (!r.recorded_sha.empty() && r.recorded_sha != r.s.sha256) {
    std::printf("  scenario differs from the recorded one (SHA-256 %.12s... vs recorded %.12s...)\n",
                r.s.sha256.c_str(), r.recorded_sha.c_str());
  }
  std::fflush(stdout);
}

/// Prints the comparison, writes replay.json and returns the exit code.
int Finish(const Replay& r, const sup::ReplayReport& report) {
  for (const auto& line : report.lines) std::printf("  %s\n", line.c_str());
  if (!report.log_error.empty()) std::fprintf(stderr, "rths replay: %s\n", report.log_error.c_str());
  int code = report.compared && !report.identical ? rths::kExitNegative : rths::kExitOk;
  if (report.failed) {
    code = g_interrupted ? rths::kExitInterrupted : (report.verdict.exit_code != 0 ? report.verdict.exit_code : rths::kExitLockstep);
    std::fprintf(stderr, "rths replay: FAILED after %lld steps: %s\n", static_cast<long long>(report.replayed),
                 g_interrupted ? "interrupted" : report.verdict.what.c_str());
  } else {
    std::printf(code == rths::kExitOk ? "identical: the live outputs reproduce the recording bit for bit\n"
                                   : "different: the live outputs differ from the recording (see above)\n");
  }
  std::ofstream(r.out / "replay.json") << report.ToJson(code).dump(2) << "\n";
  std::printf("output: %s\n", r.out.string().c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths replay: replay a recorded run into live participants (the others fed from the log, step "
               "by step, in lockstep) and compare the live outputs with the recording"};
  Options o;
  AddOptions(app, &o);
  rths::tools::NameCommand(app, "replay");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  Replay r;
  try {
    r = Prepare(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return rths::kExitUsage;
  }
  sup::RunRequest request;
  request.scenario = r.s;
  request.scenario_path = r.scenario_path;
  try {
    request.external = rths::tools::ParseExternalRoles(o.external, o.join_timeout_s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return rths::kExitUsage;
  }
  request.transport = request.external.roles.empty() ? "memq" : "mixed";
  request.lcm_url = o.url;
  request.bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  request.out = r.out;
  request.checks = false;  // Prepare did
  request.replay = sup::ReplaySource{&r.record, r.steps, r.live};
  request.summary_file = "";  // replay.json instead
  request.interrupted = &g_interrupted;
  request.on_start = [&](const sup::RunPlan& plan) {
    PrintHeader(o, r);
    if (!request.external.roles.empty()) rths::tools::PrintExternal(request, plan, r.steps);
  };
  sup::RunResult result;
  try {
    result = sup::Run(request);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return rths::kExitUsage;
  }
  const sup::ReplayFacts facts{o.run_dir, r.live, r.steps, r.s.sha256, r.recorded_sha};
  return Finish(r, sup::CompareReplay(facts, r.record, r.out, result.summary.participants, g_interrupted != 0));
}
