// rths-report RUN_DIR [--out DIR]
// A report for a run folder of `rths run` (docs/report.md; report/run_report.h): one self-contained
// HTML page, RUN_DIR/report.html (or DIR/report.html), with the scenario, the summary metrics
// (Eq. 31 tracking error, peaks, status and exit code, real-time figures of a paced run) and
// figures in figures/: time histories, tracking error, force loops, spectra and G_yr. Read from
// log.lcm (not signals.csv); a run that stopped is reported over its complete steps, and says so.
// Exit 0 written, 2 bad input (no such run folder, no or unreadable log.lcm, a bad option),
// 5 the report could not be made (gnuplot missing or failing, a file that cannot be written;
// core/exit_code.h).
#include <cstdio>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "report/run_report.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"rths report: one HTML page (report.html + figures/*.png) for a run folder of `rths run`"};
  std::string run_dir, out;
  rths::report::RunReportOptions o;
  app.add_option("run_dir", run_dir, "run folder written by `rths run` (holds log.lcm; scenario.toml and "
                                     "summary.json are used when present)")
      ->required();
  app.add_option("--out", out, "output folder for report.html and figures/ (default: RUN_DIR)");
  app.add_option("--max-plot-points", o.max_plot_points,
                 "time-history points per curve [points]: longer curves keep the min and max of each window")
      ->check(CLI::Range(std::size_t{100}, std::size_t{10000000}))
      ->capture_default_str();
  app.add_option("--welch-segment-s", o.welch_segment_s,
                 "Welch segment length aimed at [s] (a power of two of steps, at most a quarter of the run)")
      ->check(CLI::Range(1e-6, 3600.0))
      ->capture_default_str();
  app.add_option("--min-coherence", o.min_coherence, "G_yr: mask points with coherence below this [-]")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--band-db", o.band_db, "G_yr: excited band of r = where its PSD is within this of its peak [dB]")
      ->check(CLI::Range(1e-6, 200.0))
      ->capture_default_str();
  app.add_option("--gnuplot", o.gnuplot, "plotting program (a name on PATH or a path)")->capture_default_str();
  rths::tools::NameCommand(app, "report");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  o.out_dir = out;
  o.gnuplot = rths::tools::ProgramOnPath(o.gnuplot);

  rths::report::RunData data;
  try {
    data = rths::report::LoadRunData(run_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths report: %s\n", e.what());
    return rths::kExitUsage;
  }
  try {
    const rths::report::ReportFiles files = rths::report::WriteRunReport(data, o);
    std::printf("rths report: %s: %lld of %lld steps%s -> %s (%zu figures)\n", run_dir.c_str(),
                static_cast<long long>(files.steps), static_cast<long long>(files.steps_planned),
                files.complete ? "" : " (the run did not finish)", files.html.string().c_str(), files.figures.size());
    for (const auto& w : files.warnings) std::printf("  note: %s\n", w.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths report: %s\n", e.what());
    return rths::kExitInternal;
  }
  return 0;
}
