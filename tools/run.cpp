// rths-run: `rths run`, the command-line front of the supervisor (supervisor/run.h,
// docs/lockstep.md): parses the options, loads the scenario, asks supervisor::Run for the run and
// prints what it did. Exits with the run's code, naming the participant to blame.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "ident/design_model.h"
#include "core/progress.h"
#include "core/exit_code.h"
#include "report/run_report.h"
#include "scenario/scenario.h"
#include "supervisor/run.h"
#include "supervisor/run_text.h"
#include "cli.h"
#include "external_block.h"
#include "run_flags.h"
#include "set_hint.h"

namespace fs = std::filesystem;
namespace sup = rths::supervisor;
using Options = rths::tools::RunFlags;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

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
  o.Add(app);
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
  rths::tools::RunWatch watch(o.watch_flags, "rths monitor: " + request.scenario.run.name);
  if (o.watch && request.transport != "udpm") {
    // The run's own process feeds the page: its clock's records through a lock-free ring.
    try {
      request.live_sink = watch.InProcessSink();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rths run: --watch: %s\n", e.what());
      return rths::kExitUsage;
    }
  }
  request.on_start = [&](const sup::RunPlan& plan) {
    if (!o.quiet) PrintHeader(o, plan);
    if (!request.external.roles.empty()) rths::tools::PrintExternal(request, plan, plan.scenario.steps());
    if (o.watch) watch.Start(plan.url);  // a monitor that cannot start: nothing runs (RunError, exit 2)
    std::fflush(stdout);
  };
  try {
    const sup::RunResult result = sup::Run(request);
    const auto& sum = result.summary;
    watch.End(result.plan.run_id, sum.status,
              sum.status == "interrupted" ? "the operator (Ctrl-C)" : sum.failure ? sum.failure->participant : "",
              sum.stopped, sum.steps);
    return PrintEnd(o, result);
  } catch (const sup::RunError& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return e.exit_code();
  }
}
