// rths-run: `rths run`, the command-line front of the supervisor (supervisor/run.h,
// docs/lockstep.md): parses the options, loads the scenario, asks supervisor::Run for the run and
// prints what it did. Exits with the run's code, naming the participant to blame.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "ident/design_model.h"
#include "core/progress.h"
#include "core/exit_code.h"
#include "lockstep/transport.h"
#include "report/run_report.h"
#include "scenario/scenario.h"
#include "supervisor/run.h"
#include "supervisor/run_text.h"
#include "cli.h"
#include "external_block.h"
#include "watch_flags.h"
#include "set_hint.h"

namespace fs = std::filesystem;
namespace sup = rths::supervisor;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

/// The command line.
struct Options {
  std::string scenario_path, default_scenario = "scenarios/default.toml";
  std::string out, transport, bin_dir, url, external;  ///< transport "": ResolveTransport
  bool quiet = false, skip_space_check = false, port_per_channel = false, realtime = false;
  bool compact = false, report = false, watch = false;
  rths::tools::WatchFlags watch_flags;
  std::int64_t run_id = 0;
  double join_timeout_s = 120.0;
  std::vector<std::string> sets;
};

void AddOptions(CLI::App& app, Options* o) {
  app.add_option("scenario", o->scenario_path, "scenario TOML file (default: scenarios/default.toml)");
  app.add_option("--default-scenario", o->default_scenario, "used when no scenario is given")->group("");
  app.add_option("--out", o->out, "output folder (default: a new folder under runs/)");
  app.add_option("--transport", o->transport,
                 "udpm: one process per participant (the default); memq: one process (the default of a paced "
                 "run, --realtime: it holds the pace best; docs/realtime.md); mixed: the built-in participants "
                 "in one process, bridged to the --external ones on udpm (the default with --external; "
                 "docs/lockstep.md, Transports)")
      ->check(CLI::IsMember({"udpm", "memq", "mixed"}));
  app.add_option("--bin-dir", o->bin_dir, "where the rths-* programs are (default: next to this one)");
  app.add_flag("--quiet", o->quiet, "print only the output folder");
  app.add_option("--lcm-url", o->url,
                 "udpm URL of the run (default: udpm://239.255.76.67:<a free port>?ttl=0); ttl=1 to reach "
                 "participants on other hosts of the LAN (docs/participant.md)");
  app.add_flag("--port-per-channel", o->port_per_channel,
               "udpm: carry each channel on its own UDP port (the run's port + 0..6), so each process "
               "receives only the channels it reads: fewer deliveries per step, a faster run; the same "
               "payloads (as --lcm-url 'udpm://239.255.76.67:PORT?ttl=0&port_per_channel=1'; "
               "docs/lockstep.md, Transports)");
  app.add_option("--run-id", o->run_id, "run id every participant must use (default: random)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{0x3fffffffffffffff}));
  app.add_option("--external", o->external,
                 "ROLE[,ROLE...]: do not start these participants (controller, plant, semiactive); wait "
                 "for the user's own to join the handshake (docs/participant.md)");
  app.add_flag("--realtime", o->realtime,
               "pace the run to the wall clock at the scenario's dt (as [realtime] enabled = true): "
               "latency percentiles and deadline misses in summary.json (docs/realtime.md)");
  app.add_option("--join-timeout-s", o->join_timeout_s,
                 "with --external: how long to wait for the external participants to say HELLO [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_flag("--skip-space-check", o->skip_space_check, "tests only: do not check the free disk space first")
      ->group("");
  app.footer("Exit codes: 0 ok; 2 bad input or not enough disk (nothing ran); 3 a participant stopped "
             "answering (named); 4 stopped by an abort; 5 a participant's computation failed; 6 stopped "
             "by the safety monitor; 7 the output could not be written (disk full); 8 real-time mode: too many "
             "consecutive deadline misses; 9 an external participant sent ABORT; 10 an external participant was lost "
             "(heartbeats stopped, or its process ended unseen); 128+N a participant was killed by signal N; 130 "
             "interrupted.");
  rths::tools::AddSetOption(app, &o->sets);
  app.add_flag("--compact", o->compact,
               "no signals.csv (as --set run.csv_every=0): log.lcm alone holds every step; `rths export` makes "
               "a CSV or .mat of it when needed");
  app.add_flag("--report", o->report, "at the end, write RUN_DIR/report.html with figures (as `rths report RUN_DIR`)");
  app.add_flag("--watch", o->watch,
               "watch the run live in a browser, with an ABORT button: prints the monitor's address "
               "(http://127.0.0.1:8765/?token=...; any transport; docs/monitor.md)");
  o->watch_flags.Add(app, "--watch-");
}

/// The transport asked for, or the default (sup::DefaultTransport), into o->transport.
void ResolveTransport(Options* o, bool paced) {
  if (o->transport.empty()) o->transport = sup::DefaultTransport(!o->external.empty(), paced, o->url, o->port_per_channel);
}

/// The request from the options: the scenario loaded (with --set, --compact and --realtime).
sup::RunRequest RequestOf(Options& o) {
  sup::RunRequest r;
  // The command line's own contradictions first, before the scenario is read: only a run with no
  // transport option waits for the scenario's pace to choose (and then nothing here can fail).
  const bool pace_decides = o.transport.empty() && o.external.empty() && o.url.empty() && !o.port_per_channel;
  if (!pace_decides) ResolveTransport(&o, false);
  r.external = rths::tools::ParseExternalRoles(o.external, o.join_timeout_s);
  r.lcm_url = o.url;
  r.port_per_channel = o.port_per_channel;
  r.transport = pace_decides ? "udpm" : o.transport;  // pace_decides: every transport goes with these options
  if (std::string why; !r.IsValid(&why)) throw std::runtime_error(why);
  r.scenario_path = o.scenario_path;
  r.scenario = rths::scenario::LoadScenario(o.scenario_path, o.sets);
  if (o.realtime) r.scenario.realtime.enabled = true;
  ResolveTransport(&o, r.scenario.realtime.enabled);
  if (!o.sets.empty()) {
    // The scenario that runs is the file with the overrides: written out in full (file paths
    // absolute), loaded back so its hash is the file's, and given to every participant.
    r.scenario_header = o.scenario_path + " with";
    for (const auto& set : o.sets) r.scenario_header += " --set " + set;
  }
  // A model-based controller designs on the plant it drives (the benchmark's Gp where the file
  // leaves controller.model at its default): the model is then part of the scenario that runs.
  const auto model_before = r.scenario.controller.model;
  const std::string design_note = rths::ident::ResolveDesignModel(&r.scenario);
  if (!design_note.empty()) std::printf("rths run: %s\n", design_note.c_str());
  if (!(r.scenario.controller.model == model_before)) {
    r.scenario_header = (r.scenario_header.empty() ? o.scenario_path + " with" : r.scenario_header) +
                        " controller.model fitted to the benchmark plant's Gp";
  }
  r.transport = o.transport;
  r.out = o.out;
  r.bin_dir = o.bin_dir.empty() ? fs::read_symlink("/proc/self/exe").parent_path() : fs::path(o.bin_dir);
  r.run_id = o.run_id;
  if (o.realtime) r.role_args.push_back("--realtime");
  r.check_disk_space = !o.skip_space_check;
  r.progress = rths::ProgressLine::StderrIsTerminal();
  r.interrupted = &g_interrupted;
  r.on_warning = [](const std::string& w) { std::fprintf(stderr, "rths run: warning: %s\n", w.c_str()); };
  return r;
}

/// What the run will be, before it starts (sup::PlanHeader), the scenario as the user named it.
void PrintHeader(const Options& o, const sup::RunPlan& plan) {
  std::string shown = o.scenario_path;
  for (const auto& set : o.sets) shown += " --set " + set;
  std::fputs(sup::PlanHeader(plan, shown, o.transport).c_str(), stdout);
}

/// The report of what was logged (also of a run that stopped: its complete steps). A report that
/// cannot be made is a warning; the run's exit code stays the run's.
void WriteReport(const fs::path& out) {
  try {
    rths::report::RunReportOptions options;
    options.gnuplot = rths::tools::ProgramOnPath(options.gnuplot);
    const auto files = rths::report::WriteRunReport(out, options);
    std::printf("report: %s (%zu figures)\n", files.html.string().c_str(), files.figures.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: warning: no report: %s\n", e.what());
  }
}

/// The closing lines: the summary, the report, how the run ended and where its output is.
int PrintEnd(const Options& o, const sup::RunResult& result) {
  const auto& sum = result.summary;
  const fs::path& out = result.plan.out;
  if (!o.quiet) std::fputs(sum.Report(result.plan.scenario.run.dt_s).c_str(), stdout);
  std::fflush(stdout);
  if (!result.summary_written) std::fprintf(stderr, "rths run: could not write %s\n", (out / "summary.json").c_str());
  if (o.report && sum.steps > 0) WriteReport(out);
  if (sum.exit_code == 0) {
    std::printf("output: %s\n", out.string().c_str());
    return 0;
  }
  std::fprintf(stderr, "rths run: %s\n", sup::EndMessage(sum, g_interrupted != 0).c_str());
  if (sum.steps > 0) {
    std::printf("output: %s (log complete up to step %lld)\n", out.string().c_str(), static_cast<long long>(sum.steps) - 1);
  } else {
    std::printf("output: %s (no step completed)\n", out.string().c_str());
  }
  return sum.exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths run: start a lockstep RTHS run (integrator, controller, plant, semiactive, "
               "logger), wait for it, and write its output folder"};
  Options o;
  AddOptions(app, &o);
  rths::tools::NameCommand(app, "run");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) {
    if (code == rths::kExitUsage) rths::tools::PrintSetHints(app, argc, argv, "run");
    return code;
  }
  if (o.scenario_path.empty()) o.scenario_path = o.default_scenario;
  if (o.compact) o.sets.push_back("run.csv_every=0");

  sup::RunRequest request;
  try {
    request = RequestOf(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::kExitUsage;
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::unique_ptr<rths::monitor::Monitor> monitor;
  const std::string title = "rths monitor: " + request.scenario.run.name;
  if (o.watch && request.transport != "udpm") {
    // The run's own process feeds the page: its clock's records through a lock-free ring.
    try {
      monitor = std::make_unique<rths::monitor::Monitor>(o.watch_flags.Options("", title));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rths run: --watch: %s\n", e.what());
      return rths::kExitUsage;
    }
    request.live_sink = monitor->live_sink();
  }
  request.on_start = [&](const sup::RunPlan& plan) {
    if (!o.quiet) PrintHeader(o, plan);
    if (!request.external.roles.empty()) rths::tools::PrintExternal(request, plan, plan.scenario.steps());
    // A monitor that cannot start stops the run before its participants do (RunError, exit 2).
    if (o.watch) {
      try {
        if (!monitor) monitor = o.watch_flags.Make(plan.url, title);  // udpm: it listens to the run's URL
        o.watch_flags.Announce(monitor.get(), "run", stdout);
      } catch (const std::exception& e) {
        throw rths::Error("--watch", e.what());  // nothing runs: RunError, exit 2
      }
    }
    std::fflush(stdout);
  };
  try {
    const sup::RunResult result = sup::Run(request);
    if (monitor) {
      const auto& sum = result.summary;
      const std::string by = sum.status == "interrupted" ? "the operator (Ctrl-C)"
                             : sum.failure                ? sum.failure->participant
                                                          : "";
      monitor->OnEnd(result.plan.run_id, sum.status, by, sum.stopped, sum.steps);
      std::this_thread::sleep_for(std::chrono::seconds(1));  // the page gets the run's end
      monitor->Stop();
    }
    return PrintEnd(o, result);
  } catch (const sup::RunError& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return e.exit_code();
  }
}
