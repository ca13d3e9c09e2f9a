// rths-sweep: a study of the user's own (issue 28): the runs a SPEC defines (lib/sweep/spec.h), on
// this machine `--jobs` at a time (lib/sweep/run_sweep.h) or as a Slurm job array
// (lib/sweep/slurm.h), one row per run and a table.
//
//   rths sweep SPEC.toml [--out DIR] [--jobs N] [--only INDEX] [--resume] [--keep-logs]
//   rths sweep SPEC.toml --executor slurm --out DIR [--partition P] [--time T] [--account A]
//                        [--runs-per-task R] [--cpus-per-task C] [--retries N] [--detach] [--resume]
//   rths sweep --collect DIR [--retries N]
//   rths sweep SPEC.toml --out DIR --task --chunk C --chunks N   (what one array task runs)
#include <unistd.h>

#include <cstdio>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "slurm_flags.h"
#include "core/error.h"
#include "io/output_folder.h"
#include "core/exit_code.h"
#include "io/plot.h"
#include "sweep/run_sweep.h"
#include "sweep/slurm.h"
#include "sweep/study_on_slurm.h"

namespace {

/// Ascending indices as ranges: {0, 1, 2, 5, 7, 8} -> "0-2, 5, 7-8".
std::string IndexRanges(const std::vector<std::int64_t>& v) {
  std::string out;
  for (std::size_t a = 0; a < v.size();) {
    std::size_t b = a;
    while (b + 1 < v.size() && v[b + 1] == v[b] + 1) ++b;
    out += (out.empty() ? "" : ", ") + (a == b ? std::to_string(v[a]) : std::to_string(v[a]) + "-" + std::to_string(v[b]));
    a = b + 1;
  }
  return out;
}

void WarnAbsent(const std::vector<std::string>& fields) {
  for (const std::string& f : fields) {
    std::fprintf(stderr, "rths sweep: warning: no completed run's summary.json has the recorded field \"%s\" "
                         "(misspelt? docs/sweeps.md lists the fields)\n", f.c_str());
  }
}

/// Says so when DIR/plots/ stays empty because gnuplot is missing here (a cluster node, the bundle of
/// scripts/bundle.sh): the table is the result, and `--resume` where gnuplot is draws the figures.
/// `redo` is the command that writes the table and figures again without running anything.
void NoteNoPlots(const std::string& redo) {
  if (rths::io::GnuplotAvailable()) return;
  std::printf("plots/: none drawn: gnuplot is not installed here (apt-get install gnuplot-nox). The table is the "
              "result; to draw them, on a machine with gnuplot: %s (it runs nothing again)\n", redo.c_str());
}

struct Args {
  std::string spec_path, out, executor = "local", collect, batch;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::int64_t only = -1, chunk = 0, chunks = 1;
  bool resume = false, keep_logs = false, task = false, detach = false, dry_run = false;
  rths::tools::SlurmFlags slurm;  // override the SPEC's [slurm]
};

rths::sweep::SlurmRunOptions SlurmOptions(const Args& a, const rths::sweep::Spec* spec) {
  rths::sweep::SlurmRunOptions o;
  o.out = std::filesystem::absolute(a.out.empty() ? a.collect : a.out);
  o.settings = a.slurm.Applied(spec ? spec->slurm : rths::sweep::SlurmSettings{});
  o.sweep_program = rths::tools::SweepProgram();
  o.programs = a.dry_run ? rths::sweep::SlurmPrograms{} : rths::tools::SlurmProgramsOnPath();
  o.dry_run = a.dry_run;
  o.keep_logs = a.keep_logs;
  o.detach = a.detach;
  o.resume = a.resume;
  o.poll_s = a.slurm.poll_s;
  o.say = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  return o;
}

int Report(const rths::sweep::SlurmOutcome& r, const std::string& out) {
  if (!r.dry_run_command.empty()) {
    std::printf("dry run: nothing submitted; the job script every array task runs: %s/slurm/task.sh\n"
                "sbatch would be called as:\n  %s\n", out.c_str(), r.dry_run_command.c_str());
    return 0;
  }
  WarnAbsent(r.absent_fields);
  if (r.detached) {
    std::printf("detached: collect the sweep with: rths sweep --collect %s\n", out.c_str());
    return 0;
  }
  std::printf("rows %lld/%lld, not completed %lld, array tasks still failing %zu\ntable: %s\n",
              static_cast<long long>(r.rows), static_cast<long long>(r.runs), static_cast<long long>(r.not_completed),
              r.failed_tasks.size(), r.table.string().c_str());
  NoteNoPlots("rths sweep --collect " + out);
  return r.rows < r.runs || r.not_completed > 0 ? rths::kExitNegative : rths::kExitOk;
}

int RunLocal(const Args& a, const rths::sweep::Spec& spec) {
  rths::sweep::SweepOptions o;
  o.out = a.out.empty() ? rths::io::NewOutputFolder("sweep-" + spec.name) : std::filesystem::path(a.out);
  o.jobs = a.jobs;
  if (a.only >= 0) o.only = a.only;
  o.resume = a.resume || a.task;
  o.keep_logs = a.keep_logs;
  o.chunk = a.chunk;
  o.chunks = a.chunks;
  o.write_table = !a.task;
  rths::ProgressLine line("rths sweep", !a.task && rths::ProgressLine::StderrIsTerminal());
  o.progress = &line;
  std::printf("rths sweep: %s: %lld runs (%zu cases x %lld grid points x %lld draws), %d at a time\n",
              spec.path.c_str(), static_cast<long long>(spec.runs()), spec.cases.size(),
              static_cast<long long>(spec.combinations()), static_cast<long long>(std::max<std::int64_t>(spec.draws, 1)),
              a.jobs);
  std::fflush(stdout);
  const auto r = rths::sweep::RunSweep(spec, o);
  std::printf("ran %lld (not completed %lld), skipped %lld (rows already there)\n", static_cast<long long>(r.ran),
              static_cast<long long>(r.failed), static_cast<long long>(r.skipped));
  if (!r.kept.empty()) std::printf("kept (--resume): runs %s\n", IndexRanges(r.kept).c_str());
  for (const auto& note : r.design_notes) {
    std::fprintf(note.rfind("warning:", 0) == 0 ? stderr : stdout, "rths sweep: %s\n", note.c_str());
  }
  if (r.table.empty()) return r.failed > 0 ? rths::kExitNegative : rths::kExitOk;
  WarnAbsent(r.absent_fields);
  std::printf("rows %lld/%lld, not completed %lld\ntable: %s (and table.h5, summary.csv, plots/)\n",
              static_cast<long long>(r.rows), static_cast<long long>(spec.runs()),
              static_cast<long long>(r.not_completed), r.table.string().c_str());
  NoteNoPlots("rths sweep " + spec.path + " --out " + r.table.parent_path().string() + " --resume");
  // The exit code speaks for the whole sweep (rows of earlier attempts too), or for the one run asked.
  if (a.only >= 0 || a.chunks > 1) return r.failed > 0 ? rths::kExitNegative : rths::kExitOk;
  return r.not_completed > 0 || r.rows < spec.runs() ? rths::kExitNegative : rths::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths sweep: run a SPEC's grid, cases and random draws on this machine or on Slurm; a row per run and a table"};
  rths::tools::NameCommand(app, "sweep");
  Args a;
  app.add_option("spec", a.spec_path, "the sweep's SPEC (TOML; docs/sweeps.md)");
  app.add_option("--out", a.out, "output folder (default: runs/<time>-sweep-<name>; with slurm: required, shared with the nodes)");
  app.add_option("--executor", a.executor, "where the runs run: local (this machine) or slurm (a job array)")
      ->check(CLI::IsMember({"local", "slurm"}));
  app.add_option("--jobs", a.jobs, "local: runs at a time (default: every core)")->check(CLI::Range(1, 4096));
  app.add_option("--only", a.only, "make run INDEX alone (bit for bit as in the whole sweep)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  app.add_flag("--resume", a.resume, "run (local) or submit (slurm) only the runs with no row in OUT/rows yet");
  app.add_flag("--keep-logs", a.keep_logs, "keep every run's log.lcm and signals.csv");
  app.add_option("--chunk", a.chunk, "run only the indices i with i % CHUNKS == CHUNK (one task of a job array)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  app.add_option("--chunks", a.chunks, "the number of chunks the sweep is split into")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40));
  app.add_flag("--task", a.task, "run as one array task: --resume, no table, no progress line");
  a.slurm.Add(app);
  app.add_flag("--dry-run", a.dry_run, "slurm: write OUT/slurm/task.sh and print the sbatch command; submit nothing");
  app.add_flag("--detach", a.detach, "slurm: submit and return; then `rths sweep --collect OUT`");
  app.add_option("--collect", a.collect, "slurm: wait for a detached sweep in DIR, retry, write its table");
  app.add_option("--batch", a.batch, "run chunk --chunk of a study's batch file (what `rths reproduce --executor slurm` "
                                    "submits; with --task)");
  app.footer("Exit codes: 0 every run completed; 1 some runs did not (their rows, or the missing tasks, say why); 2 bad input.");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    if (!a.batch.empty()) {
      if (!a.task) throw rths::Error("--batch", "is what an array task runs: give --task with it");
      const auto made = rths::sweep::RunBatchTask(a.batch, a.chunk, a.chunks, a.jobs);
      std::printf("made %lld runs of %s (chunk %lld of %lld)\n", static_cast<long long>(made), a.batch.c_str(),
                  static_cast<long long>(a.chunk), static_cast<long long>(a.chunks));
      return 0;
    }
    if (!a.collect.empty()) {
      if (!a.spec_path.empty()) throw rths::Error("--collect", "takes the sweep's folder only, not a SPEC");
      return Report(rths::sweep::CollectSweep(SlurmOptions(a, nullptr), a.slurm.retries), a.collect);
    }
    if (a.spec_path.empty()) throw rths::Error("rths sweep", "needs a SPEC (or --collect DIR)");
    const rths::sweep::Spec spec = rths::sweep::LoadSpec(a.spec_path);
    if (a.resume && a.out.empty()) throw rths::Error("--resume", "needs --out DIR, the sweep's folder to resume");
    if (a.dry_run && a.executor != "slurm") throw rths::Error("--dry-run", "is for --executor slurm");
    if (a.executor == "local") return RunLocal(a, spec);
    if (a.out.empty()) throw rths::Error("--executor slurm", "needs --out DIR on a filesystem the compute nodes share");
    if (a.only >= 0 || a.task || a.chunks != 1) {
      throw rths::Error("--executor slurm", "--only, --task and --chunk/--chunks are for the local executor");
    }
    std::printf("rths sweep: %s: %lld runs on Slurm\n", spec.path.c_str(), static_cast<long long>(spec.runs()));
    std::fflush(stdout);
    return Report(rths::sweep::RunSweepOnSlurm(spec, SlurmOptions(a, &spec)), a.out);
  } catch (const rths::Interrupted& e) {  // Ctrl-C, e.g. while gnuplot draws
    std::fprintf(stderr, "rths sweep: %s (interrupted; nothing after it was written)\n", e.what());
    return rths::kExitInterrupted;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths sweep: %s\n", e.what());
    return rths::kExitUsage;
  }
}
