// rths-reproduce: `rths reproduce NAME [--out DIR] [--quick] [--plant physical|linear] [--jobs N] [--extended]`.
//
// Reproduces one figure or table of the paper (docs/experiments.md) into a new folder: CSV tables,
// Markdown, PNG figures and, for the lockstep studies, every run's folder. The work is done by
// lib/studies (one header per study); this file parses options and prints.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli.h"
#include "slurm_flags.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "io/output_folder.h"
#include "studies/study_table.h"
#include "sweep/study_on_slurm.h"
#include "set_hint.h"

namespace fs = std::filesystem;

namespace {

/// Ctrl-C or SIGTERM: the batch's runs stop, and so does any figure still to draw.
void OnSignal(int) { rths::RequestInterrupt(); }

struct Options {
  std::string name, out, plant = "physical";
  bool quick = false, extended = false, keep_logs = false, compact = false, resume = false;
  int jobs = 2;
  std::vector<std::string> sets;
  std::string executor = "local";         // local | slurm (lib/sweep/study_on_slurm.h)
  rths::tools::SlurmFlags slurm;          // --partition, --time, --account, --runs-per-task, ... --poll-s
};

void AddOptions(CLI::App& app, Options* o) {
  app.add_option("name", o->name, "what to reproduce")
      ->required()
      ->check(CLI::IsMember(rths::studies::StudyNames()));
  app.add_option("--out", o->out, "output folder (default: a new folder under runs/); never overwritten");
  app.add_flag("--resume", o->resume,
               "finish the study an interrupted `rths reproduce NAME --out DIR` left in DIR: the runs that ended "
               "are taken as they are, the others made again (the same tables as an uninterrupted study)");
  app.add_flag("--quick", o->quick, "shorter records (for tests; numbers are noisier)");
  app.add_flag("--extended", o->extended,
               "table2: also the extended table (table2_extended.csv/.md/.png): ats, ambc and a PI + phase lead "
               "beside none, ff and ff_lqg; the paper's 36 rows unchanged");
  app.add_flag("--keep-logs", o->keep_logs,
               "benchmark: keep every perturbed run's log.lcm (default: removed once scored; about 72 MB per run)");
  app.add_option("--plant", o->plant, "plant for the lockstep runs (not benchmark: it has its own plant)")
      ->check(CLI::IsMember({"physical", "linear"}))
      ->capture_default_str();
  app.add_option("--jobs", o->jobs, "lockstep groups run at the same time")->check(CLI::Range(1, 64))->capture_default_str();
  rths::tools::AddSetOption(app, &o->sets)->description(
      "KEY=VALUE: override a scenario key of every lockstep run of the study (dotted, e.g. plant.noise_y_mm_rms=0.01), "
      "after the study set its own keys; repeatable; checked like a file (docs/scenarios.md)");
  app.add_flag("--compact", o->compact, "runs without signals.csv (as --set run.csv_every=0): log.lcm only, about 70 % of the size");
  app.add_option("--executor", o->executor, "where the lockstep runs run: local (--jobs at a time) or slurm (a job "
                                            "array; --out on a filesystem the nodes share; docs/cluster.md)")
      ->check(CLI::IsMember({"local", "slurm"}));
  o->slurm.Add(app);
}

/// --executor slurm: the study's batches as job arrays (lib/sweep/study_on_slurm.h), run by the
/// rths-sweep beside this program.
void UseSlurm(const Options& o, rths::studies::ReproduceOptions* opts) {
  rths::sweep::StudySlurmOptions s;
  s.dir = opts->out_dir;
  s.settings = o.slurm.Applied({});
  s.programs = rths::tools::SlurmProgramsOnPath();
  s.sweep_program = rths::tools::SweepProgram();
  s.poll_s = o.slurm.poll_s;
  const auto log = opts->log;
  s.say = [log](const std::string& line) {
    if (log) log(line);
  };
  opts->run_batch = [s](const std::vector<rths::studies::RunSpec>& specs, const rths::studies::Progress& progress) {
    return rths::sweep::RunSpecsOnSlurm(specs, s, progress);
  };
}

/// Runs the study named o.name (studies/study_table.h) and prints its brief report and claims.
void Reproduce(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto& study = rths::studies::StudyNamed(o.name);
  const rths::studies::StudyReport r = study.reproduce(opts);
  std::fputs(r.brief.c_str(), stdout);
  const std::string standing = rths::studies::Standing(study, o.plant, o.quick);
  for (const auto& c : r.claims) std::fputs(rths::studies::ClaimLine(c, standing).c_str(), stdout);
  std::fputs(r.after.c_str(), stdout);
}

/// The options' own checks; returns -1 to go on, or the exit code.
int CheckOptions(Options* o) {
  if (o->compact) o->sets.push_back("run.csv_every=0");
  if (!o->sets.empty() && o->name == "fig5") {
    std::fprintf(stderr, "rths reproduce fig5: --set/--compact: fig5 runs the damper model alone, no scenario\n");
    return rths::kExitUsage;
  }
  if ((!o->sets.empty() || o->executor == "slurm") && (o->name == "nonlinear" || o->name == "marths")) {
    std::fprintf(stderr, "rths reproduce %s: --set/--compact/--executor slurm: %s runs its loops in this "
                         "process, no lockstep runs\n", o->name.c_str(), o->name.c_str());
    return rths::kExitUsage;
  }
  if (o->resume && o->out.empty()) {
    std::fprintf(stderr, "rths reproduce %s: --resume needs --out DIR: the folder of the interrupted study\n",
                 o->name.c_str());
    return rths::kExitUsage;
  }
  if (o->resume && o->executor == "slurm") {
    std::fprintf(stderr, "rths reproduce %s: --resume is for local runs; a Slurm study resumes with rths sweep --collect "
                         "(docs/cluster.md)\n", o->name.c_str());
    return rths::kExitUsage;
  }
  if (o->extended && o->name != "table2") {
    std::fprintf(stderr, "rths reproduce %s: --extended is for table2 only\n", o->name.c_str());
    return rths::kExitUsage;
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths reproduce: reproduce a figure or table of Phillips & Spencer (2013) into a new folder"};
  Options o;
  AddOptions(app, &o);
  rths::tools::NameCommand(app, "reproduce");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) {
    if (code == rths::kExitUsage) rths::tools::PrintSetHints(app, argc, argv, "reproduce");
    return code;
  }
  if (const int code = CheckOptions(&o); code >= 0) return code;

  rths::studies::ReproduceOptions opts;
  opts.out_dir = o.out.empty() ? rths::io::NewOutputFolder(fmt::format("reproduce-{}{}", o.name, o.quick ? "-quick" : ""))
                               : fs::path(o.out);
  // Absolute: run folders' scenario files name the study's own files relative to themselves.
  opts.out_dir = fs::absolute(opts.out_dir).lexically_normal();
  opts.quick = o.quick;
  opts.plant = o.plant;
  opts.jobs = o.jobs;
  opts.overrides = o.sets;
  opts.extended = o.extended;
  opts.keep_logs = o.keep_logs;
  opts.batch.interrupted = rths::InterruptFlag();
  opts.batch.resume = o.resume;
  opts.gnuplot = rths::tools::ProgramOnPath("gnuplot");
  if (const char* dir = std::getenv("RTHS_SOURCE_DIR"); dir != nullptr && *dir != '\0') opts.source_dir = dir;
  rths::ProgressLine progress("rths reproduce " + o.name);
  opts.progress = &progress;
  opts.log = [&progress](std::string_view line) {
    progress.Finish();  // the line is redrawn at the next update, under this one
    std::printf("%.*s\n", static_cast<int>(line.size()), line.data());
    std::fflush(stdout);
  };
  const auto t0 = std::chrono::steady_clock::now();
  try {
    if (o.executor == "slurm") UseSlurm(o, &opts);
    std::printf("rths reproduce %s%s%s -> %s\n", o.name.c_str(), o.quick ? " (quick)" : "",
                o.extended ? " (extended)" : "", opts.out_dir.string().c_str());
    std::fflush(stdout);
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    Reproduce(o, opts);
  } catch (const rths::Interrupted& e) {  // a batch's runs, or a figure's gnuplot
    progress.Finish();
    std::fprintf(stderr, "rths reproduce %s: %s.\nFinish it (the runs that ended are kept): rths reproduce %s --out %s%s "
                         "--resume\n",
                 o.name.c_str(), e.what(), o.name.c_str(), opts.out_dir.string().c_str(),
                 o.quick ? " --quick" : "");
    return rths::kExitInterrupted;
  } catch (const rths::Error& e) {
    progress.Finish();
    std::fprintf(stderr, "rths reproduce %s: %s\n", o.name.c_str(), e.what());
    return rths::kExitUsage;
  } catch (const std::exception& e) {
    progress.Finish();
    std::fprintf(stderr, "rths reproduce %s: internal error: %s\n", o.name.c_str(), e.what());
    return rths::kExitInternal;
  }
  progress.Finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("time: %.1f s\noutput: %s\n", wall, opts.out_dir.string().c_str());
  return 0;
}
