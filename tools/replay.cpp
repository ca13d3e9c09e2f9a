// rths-replay: replay a recorded run into live participants and compare (docs/replay.md).
//
//   rths replay RUN_DIR --live ROLE[,ROLE...] [--out DIR] [--scenario FILE] [--steps N]
//
// The roles named live are built from the scenario (RUN_DIR/scenario.toml unless --scenario);
// the others answer each step with their recorded messages, in lockstep (participants/replay.h),
// run by the supervisor (supervisor/run.h). Then every live role's output channel is compared with
// the recording (supervisor/replay_report.h): identical, or the first differing step and the RMS
// and peak difference per field. Writes DIR/log.lcm, signals.csv, scenario.toml and replay.json.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli.h"
#include "external_block.h"
#include "core/error.h"
#include "io/reserved_file.h"
#include "core/exit_code.h"
#include "supervisor/replay_plan.h"
#include "supervisor/replay_report.h"
#include "supervisor/run.h"

namespace fs = std::filesystem;
namespace sup = rths::supervisor;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

/// The command line: what supervisor::PrepareReplay checks, and the external roles.
struct Options {
  sup::ReplayOptions replay;
  std::string external, url;
  double join_timeout_s = 120.0;
};

void AddOptions(CLI::App& app, Options* o) {
  app.add_option("run_dir", o->replay.run_dir, "recorded run folder (with log.lcm and scenario.toml)")->required();
  app.add_option("--live", o->replay.live, "ROLE[,ROLE...]: the participants to run live: integrator, controller, plant, "
                                    "semiactive (the logger always is)")
      ->required();
  app.add_option("--out", o->replay.out, "output folder (default: runs/<time>-replay-<name>)");
  app.add_option("--scenario", o->replay.scenario,
                 "scenario for the live participants (default: RUN_DIR/scenario.toml); change a parameter "
                 "here to see what it changes");
  app.add_option("--steps", o->replay.steps, "replay only the first N steps (default: every complete step)")
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

void PrintHeader(const Options& o, const sup::ReplayPlan& r) {
  std::string roles;
  for (const auto& role : r.live) roles += (roles.empty() ? "" : ",") + role;
  std::printf("rths replay: %s, %lld steps, live: %s (the others from the record)\n", o.replay.run_dir.c_str(),
              static_cast<long long>(r.steps), roles.c_str());
  if (!r.recorded_sha.empty() && r.recorded_sha != r.scenario.sha256) {
    std::printf("  scenario differs from the recorded one (SHA-256 %.12s... vs recorded %.12s...)\n",
                r.scenario.sha256.c_str(), r.recorded_sha.c_str());
  }
  std::fflush(stdout);
}

/// Prints the comparison, writes replay.json (over its reserved space: a full disk cannot take it)
/// and returns the exit code.
int Finish(const sup::ReplayPlan& r, const sup::ReplayReport& report) {
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
  const fs::path json = r.out / "replay.json";
  if (!rths::io::OverwriteFile(json.string(), report.ToJson(code).dump(2) + "\n")) {
    std::fprintf(stderr, "rths replay: could not write %s\n", json.c_str());
    if (code == rths::kExitOk || code == rths::kExitNegative) code = rths::kExitOutput;
  }
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

  sup::ReplayPlan r;
  sup::RunRequest request;
  try {
    r = sup::PrepareReplay(o.replay, [](const std::string& note) {
      std::fprintf(stderr, "rths replay: note: %s\n", note.c_str());
    });
    request.external = rths::tools::ParseExternalRoles(o.external, o.join_timeout_s);
    request.transport = request.external.roles.empty() ? "memq" : "mixed";
    request.lcm_url = o.url;
    request.replay = sup::ReplaySource{&r.record, r.steps, r.live};
    if (std::string why; !request.IsValid(&why)) throw std::runtime_error(why);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths replay: %s\n", e.what());
    return rths::kExitUsage;
  }
  request.scenario = r.scenario;
  request.scenario_path = r.scenario_path;
  request.bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  request.out = r.out;
  request.check_before_start = false;  // PrepareReplay did
  request.summary_file = "replay.json";  // reserved now, the replay's report written over it at the end
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
  const sup::ReplayFacts facts{o.replay.run_dir, r.live, r.steps, r.scenario.sha256, r.recorded_sha};
  return Finish(r, sup::CompareReplay(facts, r.record, r.out, result.summary.participants, g_interrupted != 0));
}
