// rths-replay: replay a recorded run into live participants and compare (docs/replay.md).
//
//   rths replay RUN_DIR --live ROLE[,ROLE...] [--out DIR] [--scenario FILE] [--steps N]
//
// The roles named live are built from the scenario (RUN_DIR/scenario.toml unless --scenario);
// the others answer each step with their recorded messages, in lockstep (participants/replay.h).
// Then every live role's output channel is compared with the recording: identical, or the first
// differing step and the RMS and peak difference per field. Writes DIR/log.lcm, signals.csv,
// scenario.toml and replay.json.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "core/error.h"
#include "io/log_compare.h"
#include "io/output_folder.h"
#include "io/run_log.h"
#include "lockstep/exit_code.h"
#include "lockstep/protocol.h"
#include "participants/group.h"
#include "participants/replay.h"
#include "scenario/scenario.h"

namespace fs = std::filesystem;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

constexpr int kIdentical = 0, kDiffer = 1, kBadInput = 2;

/// The scenario hash the recorded participants announced ("" if the log has no handshake).
std::string RecordedSha(const rths::io::RunLog& log) {
  for (const auto& h : log.handshakes) {
    if (!h.scenario_sha256.empty()) return h.scenario_sha256;
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths replay: replay a recorded run into live participants (the others fed from the log, step "
               "by step, in lockstep) and compare the live outputs with the recording"};
  std::string run_dir, live_arg, out_arg, scenario_arg;
  std::int64_t steps_arg = 0;
  app.add_option("run_dir", run_dir, "recorded run folder (with log.lcm and scenario.toml)")->required();
  app.add_option("--live", live_arg, "ROLE[,ROLE...]: the participants to run live: integrator, controller, plant, "
                                     "semiactive (the logger always is)")
      ->required();
  app.add_option("--out", out_arg, "output folder (default: runs/<time>-replay-<name>)");
  app.add_option("--scenario", scenario_arg,
                 "scenario for the live participants (default: RUN_DIR/scenario.toml); change a parameter "
                 "here to see what it changes");
  app.add_option("--steps", steps_arg, "replay only the first N steps (default: every complete step)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  app.footer("Exit codes: 0 the live outputs are identical to the recording; 1 they differ (first differing step, "
             "RMS and peak per field); 2 bad input (nothing ran); 3-7 the replay run failed (as rths run).");
  rths::tools::NameCommand(app, "replay");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  std::vector<std::string> live;
  rths::io::RunLog record;
  rths::scenario::Scenario s;
  fs::path out;
  std::int64_t steps = 0;
  std::string recorded_sha;
  try {
    std::stringstream ss(live_arg);
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
    const fs::path log_path = fs::path(run_dir) / "log.lcm";
    if (!fs::exists(log_path)) throw rths::Error(log_path.string(), "no such file: is this a run folder of rths run?");
    record = rths::io::ReadRunLog(log_path.string());
    const std::int64_t complete = record.CompleteSteps();
    if (complete == 0) throw rths::Error(log_path.string(), "holds no complete step: nothing to replay");
    if (!record.Complete()) {
      std::fprintf(stderr, "rths replay: note: %s: %s; replaying its %lld complete steps\n", log_path.c_str(),
                   record.TruncationReason().c_str(), static_cast<long long>(complete));
    }
    const std::string scenario_path =
        scenario_arg.empty() ? (fs::path(run_dir) / "scenario.toml").string() : scenario_arg;
    try {
      s = rths::scenario::LoadScenario(scenario_path);
    } catch (const rths::Error& e) {
      throw rths::Error(scenario_path, fmt::format("{}{}", e.what(),
                                                   scenario_arg.empty() ? " (if the recorded scenario names files by a "
                                                                          "relative path, give the original with --scenario)"
                                                                        : ""));
    }
    if (const double dt_log = record.StepS(); dt_log > 0.0 && s.run.dt_s != dt_log) {
      throw rths::Error(scenario_path, fmt::format("run.dt_s = {} s, but the recording ran at {} s: a replay compares "
                                                   "step by step, so the step must be the recording's",
                                                   s.run.dt_s, dt_log));
    }
    recorded_sha = RecordedSha(record);
    steps = std::min(complete, s.steps());
    if (steps_arg > 0) {
      if (steps_arg > steps) {
        throw rths::Error("--steps", fmt::format("{} is out of range [1, {}] (the complete steps of the log and the "
                                                 "scenario's)",
                                                 steps_arg, steps));
      }
      steps = steps_arg;
    }
    if (s.steps() != complete && steps_arg == 0) {
      std::fprintf(stderr, "rths replay: note: the scenario has %lld steps, the log %lld: replaying %lld\n",
                   static_cast<long long>(s.steps()), static_cast<long long>(complete), static_cast<long long>(steps));
    }
    out = out_arg.empty() ? rths::io::NewOutputFolder("replay-" + s.run.name) : fs::path(out_arg);
    rths::io::RequireNewOrEmptyFolder(out, "a previous replay or run");
    fs::create_directories(out);
    fs::copy_file(scenario_path, out / "scenario.toml");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return kBadInput;
  }

  std::string roles;
  for (const auto& r : live) roles += (roles.empty() ? "" : ",") + r;
  std::printf("rths replay: %s, %lld steps, live: %s (the others from the record)\n", run_dir.c_str(),
              static_cast<long long>(steps), roles.c_str());
  if (!recorded_sha.empty() && recorded_sha != s.sha256) {
    std::printf("  scenario differs from the recorded one (SHA-256 %.12s... vs recorded %.12s...)\n", s.sha256.c_str(),
                recorded_sha.c_str());
  }
  std::fflush(stdout);
  const std::int64_t run_id = rths::lockstep::NewRunId();
  std::vector<rths::participants::Outcome> outcomes;
  try {
    outcomes = rths::participants::RunReplay(s, record, steps, live, run_id, out.string(), &g_interrupted);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return kBadInput;
  }
  const auto verdict = rths::participants::Judge(outcomes);
  nlohmann::json j;
  j["run_dir"] = run_dir;
  j["live"] = live;
  j["steps"] = steps;
  j["scenario_sha256"] = s.sha256;
  j["recorded_scenario_sha256"] = recorded_sha;
  if (verdict.failed || g_interrupted) {
    j["status"] = g_interrupted ? "interrupted" : "failed";
    j["failure"] = {{"participant", verdict.role}, {"step", verdict.step}, {"what", verdict.what}};
  }

  int code = kIdentical;
  std::int64_t replayed = 0;
  try {
    const auto replay = rths::io::ReadRunLog((out / "log.lcm").string());
    replayed = replay.CompleteSteps();
    j["steps_replayed"] = replayed;
    nlohmann::json channels = nlohmann::json::object();
    for (const auto& role : live) {
      const std::string ch = rths::participants::AnswerChannelOf(role);
      const auto d = rths::io::CompareChannel(record, replay, ch, replayed);
      nlohmann::json c = {{"role", role},
                          {"steps_compared", d.steps},
                          {"identical", d.identical()},
                          {"first_difference_step", d.first_difference},
                          {"differing_steps", d.differing_steps}};
      nlohmann::json fields = nlohmann::json::object();
      for (const auto& f : d.fields) {
        fields[f.name] = {{"rms", f.rms}, {"peak", f.peak}, {"peak_step", f.peak_step}, {"recorded_rms", f.rms_a}};
      }
      c["fields"] = fields;
      channels[ch] = c;
      if (!d.identical()) code = kDiffer;
      std::printf("  live %s: %s\n", role.c_str(), rths::io::Describe(d).c_str());
    }
    j["channels"] = channels;
    j["identical"] = code == kIdentical;
  } catch (const std::exception& e) {
    j["log_error"] = e.what();
    std::fprintf(stderr, "rths replay: %s\n", e.what());
  }
  if (verdict.failed || g_interrupted) {
    code = g_interrupted ? 130 : (verdict.exit_code != 0 ? verdict.exit_code : rths::lockstep::kExitLockstep);
    std::fprintf(stderr, "rths replay: FAILED after %lld steps: %s\n", static_cast<long long>(replayed),
                 g_interrupted ? "interrupted" : verdict.what.c_str());
  } else {
    j["status"] = "completed";
    std::printf(code == kIdentical ? "identical: the live outputs reproduce the recording bit for bit\n"
                                   : "different: the live outputs differ from the recording (see above)\n");
  }
  j["exit_code"] = code;
  std::ofstream(out / "replay.json") << j.dump(2) << "\n";
  std::printf("output: %s\n", out.string().c_str());
  return code;
}
