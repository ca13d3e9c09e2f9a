// rths-reproduce: `rths reproduce NAME [--out DIR] [--quick] [--plant physical|linear] [--jobs N] [--extended]`.
//
// Reproduces one figure or table of the paper (docs/experiments.md) into a new folder: CSV tables,
// Markdown, PNG figures and, for the lockstep studies, every run's folder. The work is done by
// lib/report (report/reproduce.h); this file parses options and prints.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli.h"
#include "core/error.h"
#include "io/output_folder.h"
#include "report/reproduce.h"
#include "report/benchmark_study.h"
#include "report/studies.h"

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths reproduce: reproduce a figure or table of Phillips & Spencer (2013) into a new folder"};
  std::string name, out_arg, plant = "physical";
  bool quick = false;
  int jobs = 2;
  app.add_option("name", name, "what to reproduce")
      ->required()
      ->check(CLI::IsMember({"fig5", "fig6", "fig7", "fig8", "fig9", "fig11", "table2", "benchmark"}));
  app.add_option("--out", out_arg, "output folder (default: a new folder under runs/); never overwritten");
  app.add_flag("--quick", quick, "shorter records (for tests; numbers are noisier)");
  bool extended = false;
  app.add_flag("--extended", extended,
               "table2: also the extended table (table2_extended.csv/.md/.png): ats, ambc and a PI + phase lead "
               "beside none, ff and ff_lqg; the paper's 36 rows unchanged");
  bool keep_logs = false;
  app.add_flag("--keep-logs", keep_logs,
               "benchmark: keep every perturbed run's log.lcm (default: removed once scored; about 50 MB per full run)");
  app.add_option("--plant", plant, "plant for the lockstep runs (not benchmark: it has its own plant)")
      ->check(CLI::IsMember({"physical", "linear"}))
      ->capture_default_str();
  app.add_option("--jobs", jobs, "lockstep groups run at the same time")->check(CLI::Range(1, 64))->capture_default_str();
  std::vector<std::string> sets;
  rths::tools::AddSetOption(app, &sets)->description(
      "KEY=VALUE: override a scenario key of every lockstep run of the study (dotted, e.g. plant.noise_y_mm_rms=0.01), "
      "after the study set its own keys; repeatable; checked like a file (docs/scenarios.md)");
  bool compact = false;
  app.add_flag("--compact", compact, "runs without signals.csv (as --set run.csv_every=0): log.lcm only, about 70 % of the size");
  rths::tools::NameCommand(app, "reproduce");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  if (compact) sets.push_back("run.csv_every=0");
  if (!sets.empty() && name == "fig5") {
    std::fprintf(stderr, "rths reproduce fig5: --set/--compact: fig5 runs the damper model alone, no scenario\n");
    return rths::lockstep::kExitUsage;
  }

  if (extended && name != "table2") {
    std::fprintf(stderr, "rths reproduce %s: --extended is for table2 only\n", name.c_str());
    return rths::lockstep::kExitUsage;
  }

  rths::report::ReproduceOptions opts;
  opts.out_dir = out_arg.empty() ? rths::io::NewOutputFolder(fmt::format("reproduce-{}{}", name, quick ? "-quick" : ""))
                                  : fs::path(out_arg);
  opts.quick = quick;
  opts.plant = plant;
  opts.jobs = jobs;
  opts.overrides = sets;
  opts.extended = extended;
  rths::ProgressLine progress("rths reproduce " + name);
  opts.progress = &progress;
  opts.log = [&progress](std::string_view line) {
    progress.Finish();  // the line is redrawn at the next update, under this one
    std::printf("%.*s\n", static_cast<int>(line.size()), line.data());
    std::fflush(stdout);
  };
  const auto t0 = std::chrono::steady_clock::now();
  try {
    std::printf("rths reproduce %s%s%s -> %s\n", name.c_str(), quick ? " (quick)" : "", extended ? " (extended)" : "",
                opts.out_dir.string().c_str());
    std::fflush(stdout);
    if (name == "fig5") {
      const auto r = rths::report::ReproduceFig5(opts);
      double worst = 0.0;
      for (std::size_t i = 0; i < r.current_A.size(); ++i) {
        worst = std::max(worst, std::abs(r.ours_peak_kN[i] / r.paper_peak_kN[i] - 1.0));
      }
      PrintCheck(worst <= 0.02, "E6: the six peak forces within 2 % of the reference",
                 fmt::format("largest peak difference {:.2f} %", 100 * worst), Standing(name, plant, false));
    } else if (name == "table2") {
      const auto r = rths::report::ReproduceTable2(opts);
      std::printf("\n%-6s %-18s %7s %9s %7s %9s\n", "cond", "controller", "paper5", "ours5", "paper15", "ours15");
      for (std::size_t i = 0; i + 1 < r.rows.size(); i += 2) {
        const auto& a = r.rows[i];
        const auto& b = r.rows[i + 1];
        std::printf("%-6s %-18s %7s %9.3f %7s %9.3f\n", a.condition.c_str(), a.controller.c_str(),
                    a.paper_text.c_str(), a.ours_pct, b.paper_text.c_str(), b.ours_pct);
      }
      std::printf("\n");
      for (const auto& c : r.claims) PrintCheck(c.holds, c.text, c.detail, Standing(name, plant, quick));
      if (extended) {
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
    } else if (name == "fig9") {
      const auto r = rths::report::ReproduceFig9(opts);  // report/studies.h; table in fig9.md
      std::printf("fig9: %zu runs in %.1f s; fig9.csv, fig9.md, fig9.png\n", r.rows.size(), r.wall_s);
    } else if (name == "fig11") {
      const auto r = rths::report::ReproduceFig11(opts);  // report/studies.h; table in fig11.md
      std::printf("fig11: %zu RTHS + %zu numerical runs in %.1f s; fig11_summary.json, fig11.md, PNGs\n",
                  r.runs.size(), r.numerical.size(), r.wall_s);
    } else if (name == "benchmark") {
      const auto r = rths::report::ReproduceBenchmark(opts, keep_logs);  // report/benchmark_study.h
      const auto& published = rths::report::PublishedExampleCriteria();
      for (int c = 1; c <= 4; ++c) {
        std::printf("\ncase %d, nominal plant (J1 [ms], J2-J9 [%%]; benchmark.md has the perturbed spread)\n%-17s", c, "");
        for (int j = 1; j <= 9; ++j) std::printf(" %7s", fmt::format("J{}", j).c_str());
        std::printf("\n%-17s", "example published");
        for (int j = 0; j < 9; ++j) std::printf(" %7.*f", j == 0 ? 1 : 2, published[c - 1][j]);
        std::printf("\n");
        for (const auto& row : r.rows) {
          if (row.run != "nominal" || row.case_number != c) continue;
          std::printf("%-17s", row.controller.c_str());
          for (int j = 0; j < 9; ++j) std::printf(" %7.*f", j == 0 ? 1 : 2, row.j.At(j));
          std::printf("%s\n", row.stopped == "no" ? "" : "  (stopped)");
        }
      }
      std::printf("\n%zu runs in %.1f s; benchmark.csv, benchmark_summary.csv, benchmark_loop.csv, benchmark.md, "
                  "benchmark.png\n",
                  r.rows.size(), r.wall_s);
    } else if (name == "fig6") {
      const auto r = rths::report::ReproduceFig6(opts);
      std::printf("\n%-5s %-3s %12s %12s %8s\n", "cond", "", "paper", "ours", "diff");
      for (const auto& m : r.models) {
        const auto o = m.fit.model.ToServoModel3();
        for (auto [n, p, q] : {std::tuple{"K", m.paper.K, o.K}, {"p", m.paper.p, o.p}, {"b", m.paper.b, o.b},
                               {"c", m.paper.c, o.c}}) {
          std::printf("%-5s %-3s %12.5g %12.5g %+7.2f%%\n", m.condition.c_str(), n, p, q, 100 * (q / p - 1));
        }
      }
      std::printf("\n");
      PrintCheck(r.verdict.holds, r.verdict.text, r.verdict.detail, Standing(name, plant, quick));
    } else {
      const auto r = rths::report::ReproduceFig78(opts, name);
      std::printf("\n");
      for (const auto& c : r.checks) PrintCheck(c.holds, c.text, c.detail, Standing(name, plant, quick));
    }
  } catch (const rths::Error& e) {
    progress.Finish();
    std::fprintf(stderr, "rths reproduce %s: %s\n", name.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    progress.Finish();
    std::fprintf(stderr, "rths reproduce %s: internal error: %s\n", name.c_str(), e.what());
    return 1;
  }
  progress.Finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("time: %.1f s\noutput: %s\n", wall, opts.out_dir.string().c_str());
  return 0;
}
