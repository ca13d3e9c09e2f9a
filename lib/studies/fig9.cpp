// Fig. 9 (docs/experiments.md E4): SDOF RTHS parametric study. 6 natural frequencies x 6 controllers,
// each pair one lockstep group (in-process, memq://), `jobs` at a time; Eq. 31 on r_k, y_k.
#include "studies/fig9.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/source_tree.h"
#include "io/run_signals.h"
#include "studies/figures.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::Series;
using io::Panel;
using io::Figure;
using io::MakePanel;
using io::Plot;
using io::GnuplotAvailable;
using io::CsvWriter;
using io::FormatSig;

namespace {


std::string FreqText(double f) { return FormatSig(f, 3); }

// The controller the paper proposes for this study, drawn prominently.
constexpr const char* kFig9Proposed = "G_FF,0.0A";

}  // namespace

std::vector<Fig9Controller> Fig9Controllers() {
  return {
      {"None", ControllerKind("none")},
      {"3rd Poly 8ms", ControllerDelay("poly3", 8.0)},
      {"Lead Comp 8ms", ControllerDelay("lead", 8.0)},
      {"G_FF,0.0A + LP", ControllerModel("ff_lp", "0.0A")},
      {"G_FF,0.0A", ControllerModel("ff", "0.0A")},
      {"G_FF,avgA + LQG", ControllerModel("ff_lqg", "avg")},
  };
}

std::vector<double> Fig9FrequenciesHz() { return {0.5, 1.0, 5.0, 10.0, 20.0, 30.0}; }

double Fig9GroundRms(double f_hz) { return f_hz < 2.0 ? 1000.0 : f_hz < 7.0 ? 1500.0 : 2000.0; }

scenario::Scenario Fig9Scenario(const scenario::Scenario& base, double f_hz, const Fig9Controller& c,
                                const std::string& plant, double duration_s) {
  scenario::Scenario s = base;
  s.path.clear();
  s.sha256.clear();
  s.run.name = Slug(fmt::format("fig9 {}hz {}", FreqText(f_hz), c.name));
  s.run.duration_s = duration_s;
  s.structure.mode = models::StructureMode::kRths;
  s.structure.kind = models::StructureKind::kSdof;
  s.structure.frequency_hz = f_hz;
  s.structure.ground.rms = Fig9GroundRms(f_hz);
  s.controller = c.controller;
  s.plant.kind = ParseName(models::kPlantKindNames, plant, "--plant");
  s.plant.actuator = models::ServoPreset("0.0A");
  s.semiactive.mode = control::SemiactiveMode::kPassiveOff;
  return s;
}

Figure Fig9Figure(const Fig9Result& res, const std::string& plant, bool quick) {
  Figure fig;
  fig.name = "fig9";
  fig.panel_height_px = 600;
  Panel p = MakePanel(fmt::format("Fig. 9: RTHS tracking error, SDOF with the MR damper at 0.0 A ({} plant{})", plant,
                                  quick ? ", --quick" : ""),
                      "Natural frequency [Hz]", "RMS error, Eq. 31 [%]");
  p.log_x = true;
  p.log_y = true;
  p.key = "outside right top";  // beside the axes, never over a curve
  fig.width_px = 1200;
  p.x_range = std::make_pair(0.4, 40.0);
  Series stopped;
  stopped.title = "stopped by the safety monitor";
  stopped.with = "points pt 6 ps 3";
  stopped.color = "#D55E00";
  // The proposed controller last, so it is drawn over the others.
  std::vector<Fig9Controller> order;
  for (const auto& c : Fig9Controllers()) {
    if (c.name != kFig9Proposed) order.push_back(c);
  }
  for (const auto& c : Fig9Controllers()) {
    if (c.name == kFig9Proposed) order.push_back(c);
  }
  for (const auto& c : order) {
    Series s = StyledSeries(c.name, ControllerStyle(c.name, c.name == kFig9Proposed), "linespoints");
    for (const auto& r : res.rows) {
      if (r.controller != c.name) continue;
      s.x.push_back(r.f_hz);
      s.y.push_back(r.rms_pct > 0 ? r.rms_pct : std::nan(""));
      if (r.stopped != "no") {
        stopped.x.push_back(r.f_hz);
        stopped.y.push_back(r.rms_pct > 0 ? r.rms_pct : std::nan(""));
      }
    }
    p.series.push_back(s);
  }
  if (!stopped.x.empty()) p.series.push_back(stopped);
  p.right_margin_chars = io::KeyMarginChars({&p});
  fig.panels.push_back(p);
  return fig;
}

namespace {

/// The specs: frequency-major, controllers in Fig9Controllers() order; res->rows in the same order.
std::vector<RunSpec> Fig9Specs(const ReproduceOptions& opts, const scenario::Scenario& base, double duration,
                               Fig9Result* res) {
  std::vector<RunSpec> specs;
  for (double f : Fig9FrequenciesHz()) {
    for (const auto& c : Fig9Controllers()) {
      Fig9Row row;
      row.f_hz = f;
      row.controller = c.name;
      row.run_dir = opts.out_dir / "runs" / Slug(fmt::format("{}hz {}", FreqText(f), c.name));
      specs.push_back({fmt::format("{:>4} Hz {}", FreqText(f), c.name), Fig9Scenario(base, f, c, opts.plant, duration),
                       row.run_dir});
      res->rows.push_back(row);
    }
  }
  return specs;
}

/// The table: each row's Eq. 31 error, how it stopped and its peaks (from its log).
void Fig9Table(const std::vector<RunResult>& results, Fig9Result* res) {
  for (std::size_t j = 0; j < results.size(); ++j) {
    Fig9Row& row = res->rows[j];
    row.rms_pct = results[j].tracking_pct;
    row.stopped = StoppedText(results[j]);
    if (results[j].steps == 0 && !results[j].ok) {
      throw Error("fig9", fmt::format("{} did not run: {}", results[j].label, results[j].error));
    }
    const io::RunSignals s = io::ReadRunSignals(row.run_dir);
    const auto& r = s.At("r_mm").values;
    const auto& u = s.At("u_mm").values;
    const auto& y = s.At("y_mm").values;
    const auto& f = s.At("f_kN").values;
    for (std::size_t k = 0; k < r.size(); ++k) {
      row.peak_error_mm = std::max(row.peak_error_mm, std::abs(r[k] - y[k]));
      row.peak_u_mm = std::max(row.peak_u_mm, std::abs(u[k]));
      row.peak_y_mm = std::max(row.peak_y_mm, std::abs(y[k]));
      row.peak_f_kN = std::max(row.peak_f_kN, std::abs(f[k]));
    }
  }
}

/// fig9.csv and, if gnuplot is there, fig9.png: one curve per controller, stopped pairs marked.
void WriteCsvAndFigure(const Fig9Result& res, const ReproduceOptions& opts) {
  {
    CsvWriter csv(opts.out_dir / "fig9.csv", {"f_hz", "controller", "rms_pct", "stopped"});
    for (const auto& r : res.rows) csv.Row({FreqText(r.f_hz), r.controller, FormatSig(r.rms_pct, 4), r.stopped});
    csv.Close();
  }
  if (GnuplotAvailable(opts.gnuplot)) {
    Figure fig = Fig9Figure(res, opts.plant, opts.quick);
    fig.gnuplot = opts.gnuplot;
    Plot(fig, opts.out_dir);
  } else if (opts.log) {
    opts.log("fig9: gnuplot not found, no fig9.png (apt-get install gnuplot-nox)");
  }
}

void WriteMarkdown(const Fig9Result& res, const ReproduceOptions& opts, const safety::SafetyConfig& lim,
                   double duration) {
  std::ofstream md(opts.out_dir / "fig9.md");
  md << "# Fig. 9: SDOF RTHS parametric study\n\n"
     << fmt::format("Made by `rths reproduce fig9{} --plant {}`: {} runs of {:g} s in {:.0f} s wall time "
                    "({} at a time).\n\n",
                    opts.quick ? " --quick" : "", opts.plant, res.rows.size(), duration, res.wall_s, opts.jobs)
     << "RMS tracking error (Eq. 31) [%]; * = stopped by the safety monitor (its error is over the "
        "steps before the stop).\n\n| f_n [Hz] |";
  for (const auto& c : Fig9Controllers()) md << " " << c.name << " |";
  md << "\n|---:|";
  for (std::size_t i = 0; i < Fig9Controllers().size(); ++i) md << "---:|";
  md << "\n";
  for (double f : Fig9FrequenciesHz()) {
    md << "| " << FreqText(f) << " |";
    for (const auto& r : res.rows) {
      if (r.f_hz == f) md << " " << FormatSig(r.rms_pct, 3) << (r.stopped == "no" ? "" : "*") << " |";
    }
    md << "\n";
  }
  md << "\n## Peaks against the safety limits\n\n"
     << fmt::format("Limits: stroke {} mm (|r|, |u|, |y|), force {} kN, |r - y| {} mm, divergence of the "
                    "error peak ({}x per {} s window, {} windows, above {} mm).\n\n",
                    lim.stroke_mm, lim.force_kN, lim.max_error_mm, lim.growth_factor, lim.growth_window_s,
                    lim.growth_windows, lim.growth_floor_mm)
     << "| f_n [Hz] | controller | RMS [%] | max abs(r - y) [mm] | max abs(u) [mm] | max abs(y) [mm] | max abs(f) [kN] | stopped |\n"
     << "|---:|---|---:|---:|---:|---:|---:|---|\n";
  for (const auto& r : res.rows) {
    md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", FreqText(r.f_hz), r.controller,
                      FormatSig(r.rms_pct, 3), FormatSig(r.peak_error_mm, 3), FormatSig(r.peak_u_mm, 3),
                      FormatSig(r.peak_y_mm, 3), FormatSig(r.peak_f_kN, 3), r.stopped);
  }
}

}  // namespace

Fig9Result ReproduceFig9(const ReproduceOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  if (opts.plant != "ideal") RequirePlant(opts.plant, opts.out_dir);
  const fs::path base_file = io::FindSourceFile("scenarios/fig9_base.toml", opts.source_dir);
  const scenario::Scenario base = scenario::LoadScenario(base_file.string());
  const double duration = opts.quick ? kFig9QuickS : kFig9FullS;

  Fig9Result res;
  std::vector<RunSpec> specs = Fig9Specs(opts, base, duration, &res);
  const std::string intro = fmt::format("fig9: {} lockstep runs of {:g} s on the {} plant, {} at a time (base {})",
                                        specs.size(), duration, opts.plant, opts.jobs, base_file.string());
  const auto results = RunStudyBatch(&specs, opts, intro, [&](std::size_t done, std::size_t total, const RunResult& r) {
    if (!opts.log) return;
    opts.log(fmt::format("  [{:2}/{}] {:<28} {:9.3f} %  ({:.1f} s){}", done, total, r.label, r.tracking_pct, r.wall_s,
                         r.ok ? "" : "  STOPPED: " + StoppedText(r)));
  });
  Fig9Table(results, &res);
  WriteCsvAndFigure(res, opts);
  res.wall_s = SecondsSince(t0);
  WriteMarkdown(res, opts, base.safety, duration);
  return res;
}

}  // namespace rths::studies
