// The files of `rths reproduce benchmark` (studies/benchmark.h): CSV tables, benchmark.md and
// benchmark.png from a finished study.
#include "studies/benchmark.h"

#include <cmath>
#include <fstream>
#include <ostream>

#include <fmt/format.h>

#include "io/csv.h"
#include "io/plot.h"
#include "models/benchmark_plant.h"
#include "models/benchmark_structures.h"

namespace rths::studies {

namespace fs = std::filesystem;

namespace {

constexpr std::array<const char*, 9> kJNames = {"J1_ms",  "J2_pct", "J3_pct", "J4_pct", "J5_pct",
                                                "J6_pct", "J7_pct", "J8_pct", "J9_pct"};

/// J1 to 0.1 ms, the others to 0.01 % (the benchmark's rounding), as text.
std::string JText(double v, int i) {
  if (!std::isfinite(v)) return "nan";
  return i == 0 ? fmt::format("{:.1f}", v) : fmt::format("{:.2f}", v);
}

/// Text for a Markdown table cell: '|' escaped.
std::string MdCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string MdHeader(const std::string& first, const std::string& extra = "") {
  std::string h = "| " + first + " |";
  std::string rule = "|---|";
  for (const char* n : kJNames) h += fmt::format(" {} |", n), rule += "---:|";
  if (!extra.empty()) h += " " + extra + " |", rule += "---|";
  return h + "\n" + rule + "\n";
}

int Stable(const BenchmarkResult& res, int case_number, const std::string& controller, bool perturbed_only) {
  int n = 0;
  for (const auto& row : res.rows) {
    if (row.case_number == case_number && row.controller == controller && row.stable &&
        (!perturbed_only || row.run != "nominal"))
      ++n;
  }
  return n;
}

const BenchmarkRow* Nominal(const BenchmarkResult& res, int case_number, const std::string& controller) {
  for (const auto& row : res.rows) {
    if (row.case_number == case_number && row.controller == controller && row.run == "nominal") return &row;
  }
  return nullptr;
}

/// benchmark.csv: J1-J9 of every run.
void WriteRunsCsv(const BenchmarkResult& res, const fs::path& dir) {
  {
    std::vector<std::string> header{"case", "controller", "run"};
    for (const char* n : kJNames) header.push_back(n);
    header.push_back("stopped");
    io::CsvWriter csv(dir / "benchmark.csv", header);
    for (const auto& row : res.rows) {
      std::vector<std::string> f{std::to_string(row.case_number), row.controller, row.run};
      for (int j = 0; j < 9; ++j) f.push_back(row.criteria_ok ? JText(row.j.At(j), j) : "nan");
      f.push_back(row.stopped);
      csv.Row(f);
    }
    csv.Close();
  }
}

/// benchmark_summary.csv: per case and controller, published, nominal, mean, std, min, max.
void WriteSummaryCsv(const BenchmarkResult& res, const fs::path& dir) {
  const auto names = BenchmarkControllerNames();
  {
    std::vector<std::string> header{"case", "controller", "statistic"};
    for (const char* n : kJNames) header.push_back(n);
    header.insert(header.end(), {"stable_runs", "runs"});
    io::CsvWriter csv(dir / "benchmark_summary.csv", header);
    for (int cs = 1; cs <= 4; ++cs) {
      for (std::size_t c = 0; c < names.size(); ++c) {
        const std::string stable = std::to_string(Stable(res, cs, names[c], false));
        const std::string runs = std::to_string(res.perturbed + 1);
        auto row = [&](const std::string& stat, auto value) {
          std::vector<std::string> f{std::to_string(cs), names[c], stat};
          for (int j = 0; j < 9; ++j) f.push_back(JText(value(j), j));
          f.push_back(stable);
          f.push_back(runs);
          csv.Row(f);
        };
        if (names[c] == "example_pi_lead") row("published", [&](int j) { return PublishedExampleCriteria()[cs - 1][j]; });
        const BenchmarkRow* nom = Nominal(res, cs, names[c]);
        row("nominal", [&](int j) { return nom && nom->criteria_ok ? nom->j.At(j) : std::nan(""); });
        const auto& sp = res.spread[cs - 1][c];
        row("mean", [&](int j) { return sp[j].mean; });
        row("std", [&](int j) { return sp[j].std; });
        row("min", [&](int j) { return sp[j].min; });
        row("max", [&](int j) { return sp[j].max; });
      }
    }
    csv.Close();
  }
}

/// benchmark_loop.csv and benchmark_plants.csv: the loop's closings and the perturbed plants.
void WriteLoopAndPlantsCsv(const BenchmarkResult& res, const fs::path& dir) {
  const auto names = BenchmarkControllerNames();
  {
    std::vector<std::string> header{"case", "loop", "closing"};
    for (const char* n : kJNames) header.push_back(n);
    io::CsvWriter csv(dir / "benchmark_loop.csv", header);
    for (const auto& l : res.loops) {
      std::vector<std::string> f{std::to_string(l.case_number), l.variant, l.label};
      for (int j = 0; j < 9; ++j) f.push_back(JText(l.j.At(j), j));
      csv.Row(f);
    }
    csv.Close();
  }
  {
    io::CsvWriter csv(dir / "benchmark_plants.csv",
                      {"run", "seed", "b1_per_s", "b2_per_s2", "a3_per_s", "k_e_N_per_m", "dc_gain", "lag_1hz_ms"});
    for (const auto& row : res.rows) {
      if (row.case_number != 1 || row.controller != names[0]) continue;
      const auto m = models::BenchmarkPlant::Make(row.plant, kBenchmarkDtS);
      csv.Row({row.run, std::to_string(row.seed), fmt::format("{:.6g}", row.plant.b1), fmt::format("{:.6g}", row.plant.b2),
               fmt::format("{:.6g}", row.plant.a3), fmt::format("{:.6g}", row.plant.k_e_N_per_m),
               fmt::format("{:.5f}", m.DcGain()), fmt::format("{:.3f}", 1e3 * models::TimeLagS(m, 1.0, false))});
    }
    csv.Close();
  }
}

/// benchmark.png: J1, J2, J4 and J7 of every run, a panel each, the controllers side by side, the
/// cases in their colours: the nominal plant's run filled, the perturbed plants' open rings drawn
/// over it (and a little to its right, so that one equal to the nominal one still shows), the
/// example controller's published values (Table 3) as black diamonds to its left, runs that
/// stopped (scored over the steps they ran) crossed out. One legend, above the first panel, in a row.
void WriteFigure(const BenchmarkResult& res, const ReproduceOptions& opts) {
  const auto names = BenchmarkControllerNames();
  io::Figure fig;
  fig.name = "benchmark";
  fig.width_px = 1200;
  fig.panel_height_px = 300;
  const auto& colors = io::ReadableColors();  // cases 1-4: blue, vermillion, bluish green, reddish purple
  // J2, J4 and J7 are ratios of standard deviations (signal/benchmark_criteria.h: the mean of each
  // record removed), not of RMS values.
  const std::array<std::pair<int, const char*>, 4> panels = {
      {{0, "J1: time delay of x_m behind x_t"},
       {1, "J2: std(x_m - x_t) / std(x_t), tracking error"},
       {3, "J4: std(x_m - x_r) / std(x_r), error against the reference structure"},
       {6, "J7: std(x_n,3 - x_r,3) / std(x_r,3), floor 3 against the reference structure"}}};
  for (const auto& [j, title] : panels) {
    const bool first_panel = fig.panels.empty();
    io::Panel p = io::MakePanel(title, "", fmt::format("J{} [{}]", j + 1, j == 0 ? "ms" : "%"));
    p.x_range = std::make_pair(0.5, names.size() + 0.5);
    for (std::size_t c = 0; c < names.size(); ++c) p.x_tics.emplace_back(static_cast<double>(c + 1), names[c]);
    p.key = first_panel ? "outside top center horizontal" : "off";
    p.left_margin_chars = 10;  // the panels' axes line up
    p.log_y = j != 0;
    p.margin_fraction = 0.04;  // no marker on the frame
    // A run the safety monitor (or anything) stopped is scored over the steps it ran: crossed out.
    io::Series stopped = io::MakeSeries("stopped early", "#882255");
    stopped.with = "points pt 2 ps 2.2";
    io::Series published = io::MakeSeries("published (Table 3)", "#000000");
    published.with = "points pt 12 ps 1.8";
    std::vector<io::Series> nominal, perturbed;
    for (int cs = 1; cs <= 4; ++cs) {
      const double offset = 0.14 * (cs - 2.5);  // the case's place beside the controller's tick
      io::Series nom = io::MakeSeries(fmt::format("case {}", cs), colors[cs - 1]);
      nom.with = "points pt 7 ps 1.4";
      io::Series pert = io::MakeSeries(
          cs == 1 ? fmt::format("perturbed ({} plants{})", res.perturbed, opts.quick ? ", --quick" : "") : "",
          colors[cs - 1]);
      pert.with = "points pt 6 ps 1.3";  // open rings beside (not under) the case's nominal dot
      for (std::size_t c = 0; c < names.size(); ++c) {
        for (const auto& row : res.rows) {
          if (row.case_number != cs || row.controller != names[c] || !row.criteria_ok) continue;
          const double v = row.j.At(j);
          if (!std::isfinite(v) || (p.log_y && !(v > 0))) continue;
          io::Series& s = row.run == "nominal" ? nom : pert;
          s.x.push_back(static_cast<double>(c + 1) + offset + (row.run == "nominal" ? -0.02 : 0.045));
          s.y.push_back(v);
          if (row.stopped != "no") {
            stopped.x.push_back(s.x.back());
            stopped.y.push_back(v);
          }
        }
        const double pub = PublishedExampleCriteria()[cs - 1][j];
        if (names[c] == "example_pi_lead" && std::isfinite(pub)) {
          published.x.push_back(static_cast<double>(c + 1) + offset - 0.055);
          published.y.push_back(pub);
        }
      }
      nominal.push_back(nom);
      perturbed.push_back(pert);
    }
    // Drawing order: published and nominal first, the smaller perturbed rings over them, the
    // crosses of stopped runs last.
    p.series.push_back(published);
    p.series.insert(p.series.end(), nominal.begin(), nominal.end());
    p.series.insert(p.series.end(), perturbed.begin(), perturbed.end());
    if (!stopped.x.empty()) p.series.push_back(stopped);
    if (!p.log_y) {  // J1, a delay: 0 at the bottom, a sliver below it so that J1 = 0 sits off the frame
      double top = 0.0;
      for (const io::Series& s : p.series) {
        for (const double y : s.y) top = std::max(top, y);
      }
      if (top > 0) p.y_range = std::make_pair(-0.04 * top, 1.08 * top);
    }
    fig.panels.push_back(p);
  }
  fig.gnuplot = opts.gnuplot;
  io::Plot(fig, opts.out_dir);
}

/// One section per case: the nominal plant's criteria, then the perturbed plants' spread.
void WriteCaseSections(std::ostream& md, const BenchmarkResult& res) {
  const auto names = BenchmarkControllerNames();
  for (int cs = 1; cs <= 4; ++cs) {
    const models::BenchmarkCase& bc = models::kBenchmarkCases[cs - 1];
    md << fmt::format("## Case {} (floor mass {:g} kg, {:g} % damping)\n\nNominal plant:\n\n", cs, bc.floor_mass_kg,
                      100 * bc.zeta)
       << MdHeader("controller", "stopped");
    md << "| example_pi_lead, **published** |";
    for (int j = 0; j < 9; ++j) md << " " << JText(PublishedExampleCriteria()[cs - 1][j], j) << " |";
    md << " Table 3 of the benchmark paper |\n";
    for (const auto& name : names) {
      const BenchmarkRow* row = Nominal(res, cs, name);
      if (!row) continue;
      md << "| " << name << " |";
      for (int j = 0; j < 9; ++j) md << " " << (row->criteria_ok ? JText(row->j.At(j), j) : "nan") << " |";
      md << " " << MdCell(row->stopped) << " |\n";
    }
    md << fmt::format("\n{} perturbed plants: mean +/- standard deviation; stable runs (all steps, finite criteria) of "
                      "nominal + perturbed:\n\n",
                      res.perturbed)
       << MdHeader("controller", "stable");
    for (std::size_t c = 0; c < names.size(); ++c) {
      md << "| " << names[c] << " |";
      for (int j = 0; j < 9; ++j) {
        const auto& s = res.spread[cs - 1][c][j];
        md << " " << JText(s.mean, j) << " +/- " << JText(s.std, j) << " |";
      }
      md << fmt::format(" {} of {} |\n", Stable(res, cs, names[c], false), res.perturbed + 1);
    }
    md << "\n";
  }
}

/// "How the loop is closed": the example controller's nominal loop closed four ways.
void WriteLoopSection(std::ostream& md, const BenchmarkResult& res) {
  md << "## How the loop is closed (the example controller, nominal plant)\n\n"
     << "The same scenario closed in one process (lib/studies/benchmark_loop.h): `lockstep` as the testbed closes it "
        "(central difference, x_k+1 from the force measured at k; equal to the lockstep run above), then the "
        "reference code's differences one at a time: the numerical substructure and the reference integrated "
        "continuously by RK4 (ode4), the measured force's unit delay, its converters (2^-18 m).\n\n"
     << MdHeader("case, loop");
  for (int cs = 1; cs <= 4; ++cs) {
    for (const auto& l : res.loops) {
      if (l.case_number != cs) continue;
      md << "| " << cs << ", " << l.variant << " |";
      for (int j = 0; j < 9; ++j) md << " " << JText(l.j.At(j), j) << " |";
      md << "\n";
    }
    md << "| " << cs << ", **published** |";
    for (int j = 0; j < 9; ++j) md << " " << JText(PublishedExampleCriteria()[cs - 1][j], j) << " |";
    md << "\n";
  }
}

/// The runs that stopped, and where the published values come from.
void WriteStoppedAndPublished(std::ostream& md, const BenchmarkResult& res) {
  int stopped = 0;
  for (const auto& row : res.rows) stopped += row.stopped != "no";
  md << fmt::format("\n{} of {} runs stopped before the end (criteria over the steps they ran).\n", stopped,
                    res.rows.size());
  for (const auto& row : res.rows) {
    if (row.stopped != "no")
      md << fmt::format("- case {} {} {}: {} (after {} steps)\n", row.case_number, row.controller, row.run, row.stopped,
                        row.steps);
  }
  md << "\n## What docs/benchmark.md says, checked on these runs\n\n";
  for (const auto& c : res.claims) md << ClaimMarkdown(c);
  md << "\n## Published values\n\n"
     << "The published row of each case is Table 3 of Silva, Gomez, Maghareh, Dyke & Spencer, \"Benchmark control "
        "problem for real-time hybrid simulation\" (Mech. Syst. Signal Process. 135, 2020), as printed in the "
        "preprint shipped with the benchmark's reference package (github MECHS-RCN/BENCHMARKS, \"RTHS code RT "
        "V23.zip\", V23 of 6 Feb 2019, p. 30): the example controller, nominal plant, El Centro. The paper gives "
        "no perturbed statistics (it says the controller stayed stable over 20 random plants). Nothing here was "
        "tuned to them; docs/benchmark.md explains the differences.\n";
}

void WriteMarkdown(const BenchmarkResult& res, const ReproduceOptions& opts) {
  const auto names = BenchmarkControllerNames();
  const auto& id = res.id;
  std::ofstream md(opts.out_dir / "benchmark.md");
  md << "# The RTHS benchmark problem (Silva et al. 2020) as its reference code runs it: J1-J9\n\n"
     << fmt::format("Made by `rths reproduce benchmark{}`: {} lockstep runs (4 partitioning cases x {} controllers x "
                    "nominal + {} perturbed plants) of {:g} s (El Centro x 0.4 padded with 5 s of zeros, g = 9.81 "
                    "m/s^2) at 4096 Hz in {:.0f} s wall time ({} at a time). Criteria: docs/benchmark.md; J1 [ms], "
                    "J2-J9 [%]. J1 searches lags of 0-49 samples (0-11.96 ms): a run lagging more reads 12.0 ms.\n\n",
                    opts.quick ? " --quick" : "", res.rows.size(), names.size(), res.perturbed, res.duration_s,
                    res.wall_s, opts.jobs)
     << "## Identification and design\n\n"
     << fmt::format("A BLWN command (0-{:g} Hz, RMS 1 mm, no controller) through the nominal plant with its sensor "
                    "noise; a 3-pole model of Eq. 15 fitted to G_yu over 0.5-{:g} Hz (identify.txt, identify.toml):\n\n"
                    "    G(s) = {:.5g} / ((s + {:.5g})(s^2 + {:.5g} s + {:.5g}))\n\n"
                    "DC gain {:.4f} (the plant: {:.4f}); low-frequency lag {:.2f} ms (the plant at 1 Hz: {:.2f} ms).\n\n",
                    kBenchmarkIdBandHz, kBenchmarkFitHiHz, id.model.K, id.model.p, id.model.b, id.model.c,
                    id.fit.fit.model.DcGain(), id.plant_dc_gain, id.model_lag_ms, id.plant_lag_ms)
     << fmt::format("Controllers: `example_pi_lead`, the benchmark's example (C(s) = 2 + 95/s, T(s) = 50.83 (s + "
                    "168.6)/(s + 8570.4), Tustin: an `lti` scenario, scenarios/benchmark/caseN_example.toml); `ff` "
                    "and `ff_lqg` (default LQG weights) on the fitted model; `poly3` and `lead` compensating {:.1f} ms "
                    "(max_delay_ms raised to {:g} ms); `ats` with OpenFresco's parameters; `ambc` from "
                    "RobustAMBCvRTHS's initial model with its gains; `none`. None was tuned on these runs.\n\n",
                    id.compensated_delay_ms, BenchmarkController("poly3", id).max_delay_ms);
  WriteCaseSections(md, res);
  WriteLoopSection(md, res);
  WriteStoppedAndPublished(md, res);
}

}  // namespace

void WriteBenchmarkOutputs(const BenchmarkResult& res, const ReproduceOptions& opts) {
  WriteRunsCsv(res, opts.out_dir);
  WriteSummaryCsv(res, opts.out_dir);
  WriteLoopAndPlantsCsv(res, opts.out_dir);
  if (io::GnuplotAvailable(opts.gnuplot)) {
    WriteFigure(res, opts);
  } else if (opts.log) {
    opts.log("benchmark: gnuplot not found, no benchmark.png (apt-get install gnuplot-nox)");
  }
  WriteMarkdown(res, opts);
}

}  // namespace rths::studies
