// rths-reproduce: `rths reproduce NAME [--out DIR] [--quick] [--plant physical|linear] [--jobs N]`.
//
// Reproduces one figure or table of the paper (docs/experiments.md) into a new folder: CSV tables,
// Markdown, PNG figures and, for the lockstep studies, every run's folder. The work is done by
// lib/report (report/reproduce.h); this file parses options and prints.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <tuple>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "io/output_folder.h"
#include "report/reproduce.h"
#include "report/studies.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"rths reproduce: reproduce a figure or table of Phillips & Spencer (2013) into a new folder"};
  std::string name, out_arg, plant = "physical";
  bool quick = false;
  int jobs = 2;
  app.add_option("name", name, "what to reproduce")
      ->required()
      ->check(CLI::IsMember({"fig5", "fig6", "fig7", "fig8", "fig9", "fig11", "table2"}));
  app.add_option("--out", out_arg, "output folder (default: a new folder under runs/); never overwritten");
  app.add_flag("--quick", quick, "shorter records (for tests; numbers are noisier)");
  app.add_option("--plant", plant, "plant for the lockstep runs")
      ->check(CLI::IsMember({"physical", "linear"}))
      ->capture_default_str();
  app.add_option("--jobs", jobs, "lockstep groups run at the same time")->check(CLI::Range(1, 64))->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  rths::report::ReproduceOptions opts;
  opts.out_dir = out_arg.empty() ? rths::io::NewOutputFolder(fmt::format("reproduce-{}{}", name, quick ? "-quick" : ""))
                                  : fs::path(out_arg);
  opts.quick = quick;
  opts.plant = plant;
  opts.jobs = jobs;
  opts.log = [](std::string_view line) {
    std::printf("%.*s\n", static_cast<int>(line.size()), line.data());
    std::fflush(stdout);
  };
  const auto t0 = std::chrono::steady_clock::now();
  try {
    std::printf("rths reproduce %s%s -> %s\n", name.c_str(), quick ? " (quick)" : "", opts.out_dir.string().c_str());
    std::fflush(stdout);
    if (name == "fig5") {
      const auto r = rths::report::ReproduceFig5(opts);
      double worst = 0.0;
      for (std::size_t i = 0; i < r.current_A.size(); ++i) {
        worst = std::max(worst, std::abs(r.ours_peak_kN[i] / r.paper_peak_kN[i] - 1.0));
      }
      std::printf("fig5: largest peak difference %.2f %% (E6 holds within 2 %%: %s)\n", 100 * worst,
                  worst <= 0.02 ? "yes" : "NO");
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
      for (const auto& c : r.claims) {
        std::printf("%s %s\n    %s\n", c.holds ? "[holds]" : "[DOES NOT HOLD]", c.text.c_str(), c.detail.c_str());
      }
    } else if (name == "fig9") {
      const auto r = rths::report::ReproduceFig9(opts);  // report/studies.h; table in fig9.md
      std::printf("fig9: %zu runs in %.1f s; fig9.csv, fig9.md, fig9.png\n", r.rows.size(), r.wall_s);
    } else if (name == "fig11") {
      const auto r = rths::report::ReproduceFig11(opts);  // report/studies.h; table in fig11.md
      std::printf("fig11: %zu RTHS + %zu numerical runs in %.1f s; fig11_summary.json, fig11.md, PNGs\n",
                  r.runs.size(), r.numerical.size(), r.wall_s);
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
      std::printf("\n%s %s\n    %s\n", r.verdict.holds ? "[holds]" : "[DOES NOT HOLD]", r.verdict.text.c_str(),
                  r.verdict.detail.c_str());
    } else {
      const auto r = rths::report::ReproduceFig78(opts, name);
      std::printf("\n");
      for (const auto& c : r.checks) {
        std::printf("%s %s\n    %s\n", c.holds ? "[holds]" : "[does not hold]", c.text.c_str(), c.detail.c_str());
      }
    }
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "rths reproduce %s: %s\n", name.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths reproduce %s: internal error: %s\n", name.c_str(), e.what());
    return 1;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("time: %.1f s\noutput: %s\n", wall, opts.out_dir.string().c_str());
  return 0;
}
