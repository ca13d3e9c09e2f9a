// rths-compare RUN_A RUN_B [RUN_C ...] [--out DIR] [--labels A,B,...]
// Runs side by side (report/compare_page.h, docs/compare.md): one HTML page, DIR/compare.html, with
// the runs' summary figures in one table, the scenario keys that differ, and figures that overlay
// their time histories, tracking errors, force loops and spectra, aligned by step. Read from each
// folder's log.lcm, summary.json and scenario.toml. Exit 0 written, 2 bad input (a folder that is
// not a run, runs with different dt, an output folder that is not new or empty), 5 the page could
// not be made (gnuplot missing or failing, a file that cannot be written; core/exit_code.h).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "io/output_folder.h"
#include "report/compare_page.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"rths compare: two or more runs side by side in one HTML page (compare.html + figures/*.png): their "
               "summary figures, the scenario keys that differ, and their time histories, tracking errors, force "
               "loops and spectra overlaid, aligned by step"};
  std::vector<std::string> run_dirs;
  std::string out;
  rths::report::CompareOptions o;
  app.add_option("runs", run_dirs, "run folders written by `rths run` or `rths replay` (each holds log.lcm)")
      ->required()
      ->expected(2, 64);
  app.add_option("--out", out, "output folder, new or empty (default: compare-<A>-<B>... beside the first run)");
  app.add_option("--labels", o.labels, "A,B,...: the runs' names on the page (default: their folder names)")
      ->delimiter(',');
  app.add_option("--max-plot-points", o.max_plot_points, "time-history points per curve (min and max kept per bucket)")
      ->check(CLI::Range(std::size_t{100}, std::size_t{10000000}))
      ->capture_default_str();
  app.add_option("--welch-segment-s", o.welch_segment_s, "Welch segment length aimed at [s]")
      ->check(CLI::Range(1e-6, 3600.0))
      ->capture_default_str();
  app.add_option("--gnuplot", o.gnuplot, "plotting program (a name on PATH or a path)")->capture_default_str();
  rths::tools::NameCommand(app, "compare");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  o.gnuplot = rths::tools::ProgramOnPath(o.gnuplot);

  std::vector<rths::report::RunData> runs;
  try {
    for (const auto& d : run_dirs) runs.push_back(rths::report::LoadRunData(d));
    if (out.empty()) {
      std::string name = "compare";
      for (const auto& d : run_dirs) name += "-" + fs::absolute(d).lexically_normal().filename().string();
      out = (fs::absolute(run_dirs[0]).lexically_normal().parent_path() / name).string();
    }
    rths::io::RequireNewOrEmptyFolder(out, "--out");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths compare: %s\n", e.what());
    return rths::kExitUsage;
  }
  o.out_dir = out;
  try {
    const auto files = rths::report::WriteComparison(runs, o);
    std::printf("rths compare: %zu runs over %lld common steps -> %s (%zu figures)\n", runs.size(),
                static_cast<long long>(files.aligned_steps), files.html.string().c_str(), files.figures.size());
    if (files.differing_keys.empty()) {
      std::printf("  the scenarios are the same, key by key\n");
    } else {
      std::printf("  scenario keys that differ: %s\n", fmt::format("{}", fmt::join(files.differing_keys, ", ")).c_str());
    }
    for (std::size_t i = 0; i < runs.size(); ++i) {  // the benchmark's criteria, as the run printed them
      if (const auto c = rths::report::BenchmarkCriteriaOf(runs[i]))
        std::printf("  %s: %s\n", (i < o.labels.size() ? o.labels[i] : runs[i].run_dir.filename().string()).c_str(),
                    c->Format().c_str());
    }
  } catch (const rths::Interrupted& e) {  // Ctrl-C, e.g. while gnuplot draws
    std::fprintf(stderr, "rths compare: %s (interrupted; nothing after it was written)\n", e.what());
    return rths::kExitInterrupted;
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "rths compare: %s\n", e.what());
    return e.where() == "rths compare" || e.where() == "--labels" || e.problem().find("share dt") != std::string::npos
               ? rths::kExitUsage
               : rths::kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths compare: %s\n", e.what());
    return rths::kExitInternal;
  }
  return 0;
}
