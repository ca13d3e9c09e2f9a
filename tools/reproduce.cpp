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
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli.h"
#include "slurm_flags.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "io/output_folder.h"
#include "studies/benchmark.h"
#include "studies/fig11.h"
#include "studies/fig5.h"
#include "studies/fig6.h"
#include "studies/fig78.h"
#include "studies/fig9.h"
#include "studies/nonlinear_delay.h"
#include "studies/table2.h"
#include "sweep/study_on_slurm.h"
#include "set_hint.h"

namespace fs = std::filesystem;

namespace {

/// Whether a check of the paper's claims is one the test suite requires (it fails the tests if it
/// does not hold) or one the reproduction only reports, and why; --quick noted where it matters.
std::string Standing(const std::string& name, const std::string& plant, bool quick) {
  std::string s;
  if (name == "fig5") {
    s = "required: the test suite asserts E6 within 2 %";
  } else if ((name == "fig6" || name == "fig7" || name == "fig8") && plant == "linear") {
    s = "required on the linear plant: the test suite asserts it (with --quick)";
  } else if (name == "fig6" || name == "fig7" || name == "fig8") {
    s = "reported on the physical plant: docs/experiments.md says which hold there and why";
  } else if (name == "benchmark") {
    s = "reported: what docs/benchmark.md says, checked on these numbers";
  } else if (name == "fig11") {
    s = "reported: the paper's statement checked on our numbers (docs/reproduce_fig11.md)";
  } else if (name == "nonlinear") {
    s = "required: the test suite asserts the linear rows against the closed form (docs/reproduce_nonlinear.md)";
  } else {
    s = "reported: the paper's claim checked on our numbers (docs/experiments.md)";
  }
  if (quick) s += "; --quick: shorter records, noisier numbers than the full run";
  return s;
}

/// One check as printed: "[holds] TEXT" or "[does not hold] TEXT", its numbers, and its standing.
void PrintCheck(bool holds, const std::string& text, const std::string& detail, const std::string& standing) {
  std::printf("%s %s\n    %s\n    (%s)\n", holds ? "[holds]" : "[does not hold]", text.c_str(), detail.c_str(),
              standing.c_str());
}

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
      ->check(CLI::IsMember({"fig5", "fig6", "fig7", "fig8", "fig9", "fig11", "table2", "benchmark", "nonlinear"}));
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

void Fig5(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceFig5(opts);
  double worst = 0.0;
  for (std::size_t i = 0; i < r.current_A.size(); ++i) {
    worst = std::max(worst, std::abs(r.ours_peak_kN[i] / r.paper_peak_kN[i] - 1.0));
  }
  PrintCheck(worst <= 0.02, "E6: the six peak forces within 2 % of the reference",
             fmt::format("largest peak difference {:.2f} %", 100 * worst), Standing(o.name, o.plant, false));
}

/// The extended table: Eq. 31 in both bands per condition and controller, and why a run stopped.
void PrintTable2Extended(const rths::studies::Table2Result& r) {
  std::printf("\nextended table (Eq. 31 [%%]; table2_extended.md has the peaks, the second halves and the "
              "adaptive coefficients)\n%-6s %-8s %9s %9s  %s\n",
              "cond", "ctrl", "0-5 Hz", "0-15 Hz", "stopped");
  for (std::size_t i = 0; i < r.extended.size(); ++i) {
    const auto& a = r.extended[i];
    if (a.band != "0-5") continue;
    for (const auto& b : r.extended) {
      if (b.condition != a.condition || b.controller != a.controller || b.band != "0-15") continue;
      std::string stop;
      for (const auto* x : {&a, &b}) {
        if (x->stopped != "no") stop += fmt::format("{}{} Hz: {}", stop.empty() ? "" : "; ", x->band, x->stopped);
      }
      std::printf("%-6s %-8s %9.3f %9.3f  %s\n", a.condition.c_str(), a.controller.c_str(), a.ours_pct, b.ours_pct,
                  stop.empty() ? "no" : stop.c_str());
    }
  }
}

void Table2(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceTable2(opts);
  std::printf("\n%-6s %-18s %7s %9s %7s %9s\n", "cond", "controller", "paper5", "ours5", "paper15", "ours15");
  for (std::size_t i = 0; i + 1 < r.rows.size(); i += 2) {
    const auto& a = r.rows[i];
    const auto& b = r.rows[i + 1];
    std::printf("%-6s %-18s %7s %9.3f %7s %9.3f\n", a.condition.c_str(), a.controller.c_str(), a.paper_text.c_str(),
                a.ours_pct, b.paper_text.c_str(), b.ours_pct);
  }
  std::printf("\n");
  for (const auto& c : r.claims) PrintCheck(c.holds, c.text, c.detail, Standing(o.name, o.plant, o.quick));
  if (o.extended) PrintTable2Extended(r);
}

void Fig9(const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceFig9(opts);  // studies/fig9.h; table in fig9.md
  std::printf("fig9: %zu runs in %.1f s; fig9.csv, fig9.md, fig9.png\n", r.rows.size(), r.wall_s);
}

/// The critical-delay table (issue 44): tau_cr [ms] per integrator and structure, and the check of
/// the linear rows against the closed-form delay margin.
void Nonlinear(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceNonlinear(opts);  // studies/nonlinear_delay.h
  auto cell = [](const rths::studies::CriticalDelay& c) {
    return c.found ? fmt::format("{:.3f}", 1e3 * c.tau_s) : fmt::format("> {:.0f}", 1e3 * c.tau_s);
  };
  std::printf("\ncritical delay [ms] (critical_delay.md explains the columns)\n%-18s %-9s %8s %10s %8s %8s %8s %9s\n",
              "integrator", "structure", "none", "diverges", "poly3", "lead", "ff", "analytic");
  double worst = 0.0;
  for (const auto& row : r.rows) {
    std::printf("%-18s %-9s %8s %10s %8s %8s %8s %9s\n", row.integrator.c_str(), row.yielding ? "yielding" : "linear",
                cell(row.none).c_str(), cell(row.none_divergence).c_str(), cell(row.poly3).c_str(),
                cell(row.lead).c_str(), cell(row.ff).c_str(),
                row.yielding ? "" : fmt::format("{:.3f}", 1e3 * row.analytic.tau_s).c_str());
    // newmark_implicit holds the force one sample late: its margin is one dt shorter (the docs say why).
    if (!row.yielding && row.integrator != "newmark_implicit" && row.none.found) {
      worst = std::max(worst, std::abs(row.none.tau_s / row.analytic.tau_s - 1.0));
    }
  }
  std::printf("\n%zu searches in %.1f s; critical_delay.csv, critical_delay.md, critical_delay.png\n\n",
              r.rows.size() * rths::studies::NonlinearDelayColumns().size(), r.wall_s);
  PrintCheck(worst <= 0.02, "linear rows (central_difference, cr, alpha_os) within 2 % of the closed-form delay margin",
             fmt::format("largest difference {:.2f} %", 100 * worst), Standing(o.name, o.plant, o.quick));
}

void Fig11(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceFig11(opts);  // studies/fig11.h; table in fig11.md
  std::printf("fig11: %zu RTHS + %zu numerical runs in %.1f s; fig11_summary.json, fig11.md, PNGs\n\n", r.runs.size(),
              r.numerical.size(), r.wall_s);
  for (const auto& c : r.claims) PrintCheck(c.holds, c.text, c.detail, Standing(o.name, o.plant, o.quick));
}

void Benchmark(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceBenchmark(opts, o.keep_logs);  // studies/benchmark.h
  const auto& published = rths::studies::PublishedExampleCriteria();
  for (int c = 1; c <= 4; ++c) {
    std::printf("\ncase %d, nominal plant (J1 [ms], J2-J9 [%%]; benchmark.md has the perturbed spread)\n%-17s", c, "");
    for (int j = 1; j <= 9; ++j) std::printf(" %7s", fmt::format("J{}", j).c_str());
    std::printf("\n%-17s", "example published");
    for (int j = 0; j < 9; ++j) std::printf(" %7.*f", j == 0 ? 1 : 2, published[c - 1][j]);
    // The example closed as the reference code closes its loop: the row to hold against the
    // published one; the controllers below are lockstep runs (docs/benchmark.md says why J4-J9 differ).
    for (const auto& l : r.loops) {
      if (l.case_number != c || l.variant != "reference code") continue;
      std::printf("\n%-17s", "example ref. loop");
      for (int j = 0; j < 9; ++j) std::printf(" %7.*f", j == 0 ? 1 : 2, l.j.At(j));
    }
    std::printf("\n  lockstep runs:\n");
    for (const auto& row : r.rows) {
      if (row.run != "nominal" || row.case_number != c) continue;
      std::printf("%-17s", row.controller.c_str());
      for (int j = 0; j < 9; ++j) std::printf(" %7.*f", j == 0 ? 1 : 2, row.j.At(j));
      std::printf("%s\n", row.stopped == "no" ? "" : "  (stopped)");
    }
  }
  std::printf("\n%zu runs in %.1f s; benchmark.csv, benchmark_summary.csv, benchmark_loop.csv, benchmark.md, "
              "benchmark.png\n\n",
              r.rows.size(), r.wall_s);
  for (const auto& c : r.claims) PrintCheck(c.holds, c.text, c.detail, Standing(o.name, o.plant, o.quick));
}

void Fig6(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceFig6(opts);
  std::printf("\n%-5s %-3s %12s %12s %8s\n", "cond", "", "paper", "ours", "diff");
  for (const auto& m : r.models) {
    const auto q = m.fit.model.ToServoModel3();
    for (auto [n, p, v] : {std::tuple{"K", m.paper.K, q.K}, {"p", m.paper.p, q.p}, {"b", m.paper.b, q.b},
                           {"c", m.paper.c, q.c}}) {
      std::printf("%-5s %-3s %12.5g %12.5g %+7.2f%%\n", m.condition.c_str(), n, p, v, 100 * (v / p - 1));
    }
  }
  std::printf("\n");
  PrintCheck(r.verdict.holds, r.verdict.text, r.verdict.detail, Standing(o.name, o.plant, o.quick));
}

void Fig78(const Options& o, const rths::studies::ReproduceOptions& opts) {
  const auto r = rths::studies::ReproduceFig78(opts, o.name);
  std::printf("\n");
  for (const auto& c : r.checks) PrintCheck(c.holds, c.text, c.detail, Standing(o.name, o.plant, o.quick));
}

/// Runs the study named o.name and prints its table and checks.
void Reproduce(const Options& o, const rths::studies::ReproduceOptions& opts) {
  if (o.name == "fig5") {
    Fig5(o, opts);
  } else if (o.name == "table2") {
    Table2(o, opts);
  } else if (o.name == "fig9") {
    Fig9(opts);
  } else if (o.name == "fig11") {
    Fig11(o, opts);
  } else if (o.name == "nonlinear") {
    Nonlinear(o, opts);
  } else if (o.name == "benchmark") {
    Benchmark(o, opts);
  } else if (o.name == "fig6") {
    Fig6(o, opts);
  } else {
    Fig78(o, opts);
  }
}

/// The options' own checks; returns -1 to go on, or the exit code.
int CheckOptions(Options* o) {
  if (o->compact) o->sets.push_back("run.csv_every=0");
  if (!o->sets.empty() && o->name == "fig5") {
    std::fprintf(stderr, "rths reproduce fig5: --set/--compact: fig5 runs the damper model alone, no scenario\n");
    return rths::kExitUsage;
  }
  if ((!o->sets.empty() || o->executor == "slurm") && o->name == "nonlinear") {
    std::fprintf(stderr, "rths reproduce nonlinear: --set/--compact/--executor slurm: nonlinear runs its loops in this "
                         "process, no lockstep runs\n");
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
