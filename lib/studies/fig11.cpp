// Fig. 11 (docs/experiments.md E5): the 9-story building (one NS frame, half the seismic mass, shear
// model of docs/models.md section 8) with 18 MR dampers at the first story under El Centro NS x 0.5;
// 3 controllers x 3 semiactive modes of RTHS, plus the pure numerical simulation (plant.kind =
// "ideal": the damper model driven by the desired motion) for each semiactive mode.
#include "studies/fig11.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/run_log.h"
#include "io/csv.h"
#include "io/plot.h"
#include "io/source_tree.h"
#include "studies/figures.h"
#include "signal/metrics.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::Series;
using io::Panel;
using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Plot;
using io::GnuplotAvailable;
using io::FormatSig;

namespace {


constexpr const char* kNumerical = "Numerical";
// The paper's controller for the building (the stories figure shows its RTHS runs).
constexpr const char* kFig11Proposed = "G_FF,avgA + LQG";

// Per-run signals for the figures and the summary.
struct Fig11Trace {
  std::vector<double> t, y_mm, v_mm_s, f_kN;
};

Fig11Run Summarise(const fs::path& dir, const std::string& controller, const std::string& mode,
                   const RunResult& rr, double dt, Fig11Trace* tr) {
  Fig11Run run;
  run.controller = controller;
  run.semiactive = mode;
  run.stopped = StoppedText(rr);
  run.wall_s = rr.wall_s;
  run.run_dir = dir;
  const io::RunLog log = io::ReadRunLog((dir / "log.lcm").string());
  const io::RunMetrics m = io::ComputeMetrics(log);
  run.accel_extrapolation_rms_err_pct = m.accel_extrapolation_rms_err_pct;
  run.velocity_prediction_rms_err_pct = m.velocity_prediction_rms_err_pct;
  const std::int64_t n = log.CompleteSteps();
  run.peak_drift_mm.assign(9, 0.0);
  run.peak_abs_accel_mps2.assign(9, 0.0);
  for (std::int64_t k = 0; k < n; ++k) {
    const auto& d = log.desired[k];
    const int nd = std::min<int>(d.n_dof, 9);
    for (int i = 0; i < nd; ++i) {
      const double drift = d.x_mm[i] - (i > 0 ? d.x_mm[i - 1] : 0.0);
      run.peak_drift_mm[i] = std::max(run.peak_drift_mm[i], std::abs(drift));
      run.peak_abs_accel_mps2[i] = std::max(run.peak_abs_accel_mps2[i], std::abs(d.abs_acc_mm_s2[i]) / 1000.0);
    }
    run.damper_peak_force_kN = std::max(run.damper_peak_force_kN, std::abs(log.measured[k].f_kN));
    run.damper_peak_disp_mm = std::max(run.damper_peak_disp_mm, std::abs(log.measured[k].y_mm));
  }
  tr->t.resize(n);
  tr->y_mm.resize(n);
  tr->v_mm_s.resize(n);
  tr->f_kN.resize(n);
  for (std::int64_t k = 0; k < n; ++k) {
    tr->t[k] = k * dt;
    tr->y_mm[k] = log.measured[k].y_mm;
    tr->f_kN[k] = log.measured[k].f_kN;
  }
  for (std::int64_t k = 0; k < n; ++k) {  // damper velocity: central difference of y (one-sided at the ends)
    const std::int64_t a = std::max<std::int64_t>(k - 1, 0), b = std::min<std::int64_t>(k + 1, n - 1);
    tr->v_mm_s[k] = b > a ? (tr->y_mm[b] - tr->y_mm[a]) / ((b - a) * dt) : 0.0;
  }
  return run;
}

nlohmann::json ToJson(const Fig11Run& r) {
  nlohmann::json j;
  j["controller"] = r.controller;
  j["semiactive"] = r.semiactive;
  j["stopped"] = r.stopped;
  j["peak_drift_mm"] = r.peak_drift_mm;
  j["peak_abs_accel_mps2"] = r.peak_abs_accel_mps2;
  j["damper_peak_force_kN"] = r.damper_peak_force_kN;
  j["damper_peak_disp_mm"] = r.damper_peak_disp_mm;
  j["force_rths_vs_numerical_nrmse_pct"] = r.force_rths_vs_numerical_nrmse_pct;
  j["accel_extrapolation_rms_err_pct"] = r.accel_extrapolation_rms_err_pct;
  j["velocity_prediction_rms_err_pct"] = r.velocity_prediction_rms_err_pct;
  return j;
}

// Every `stride`-th point (the time histories hold 2000 points per second).
Series Thin(Series s, const std::vector<double>& x, const std::vector<double>& y, std::size_t stride) {
  for (std::size_t i = 0; i < x.size(); i += stride) {
    s.x.push_back(x[i]);
    s.y.push_back(y[i]);
  }
  return s;
}

}  // namespace

Figure Fig11StoriesFigure(const Fig11Result& res) {
  Figure fig;
  fig.name = "fig11_stories";
  fig.title = fmt::format("Fig. 11: peak story drifts and absolute floor accelerations (El Centro NS x 0.5): RTHS with "
                          "{} (solid) vs numerical (dashed)",
                          kFig11Proposed);
  fig.columns = 2;
  fig.width_px = 1600;
  fig.panel_height_px = 600;
  Panel drift = MakePanel("Peak story drift", "Peak drift [mm]", "Story");
  Panel acc = MakePanel("Peak absolute acceleration", "Peak acceleration [mm/s^2]", "Floor");
  // One legend, beside the right panel: the curves fill both panels.
  drift.key = "off";
  acc.key = "outside right top";
  drift.y_range = acc.y_range = std::make_pair(0.5, 9.5);
  const auto modes = Fig11SemiactiveModes();
  const std::vector<std::string> mode_colors = {"#0072B2", "#D55E00", "#009E73"};
  const std::vector<int> mode_points = {7, 5, 9};
  std::vector<double> story(9);
  for (int i = 0; i < 9; ++i) story[i] = i + 1;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    for (const auto* set : {&res.numerical, &res.runs}) {
      for (const auto& r : *set) {
        if (r.semiactive != modes[m]) continue;
        const bool num = r.controller == kNumerical;
        if (!num && r.controller != kFig11Proposed) continue;
        const std::string title = fmt::format("{}, {}", modes[m], num ? "numerical" : "RTHS");
        Series sd = MakeSeries(title, mode_colors[m % mode_colors.size()], num ? 2 : 1);
        sd.with = fmt::format("linespoints pt {} ps 1.3", num ? 6 : mode_points[m % mode_points.size()]);
        sd.width = num ? 2.0 : 1.5;
        sd.x = r.peak_drift_mm;
        sd.y = story;
        drift.series.push_back(sd);
        Series sa = sd;
        sa.x.clear();
        for (double a_mps2 : r.peak_abs_accel_mps2) sa.x.push_back(1000.0 * a_mps2);  // m/s^2 -> mm/s^2
        acc.series.push_back(sa);
      }
    }
  }
  acc.right_margin_chars = io::KeyMarginChars({&acc});
  fig.panels = {drift, acc};
  return fig;
}

std::vector<Fig11Controller> Fig11Controllers() {
  control::ControllerConfig poly = ControllerKind("poly3");
  poly.delay_ms = 9.0;
  control::ControllerConfig lqg = ControllerKind("ff_lqg");
  lqg.model = models::ServoPreset("avg");
  return {{"3rd Poly 9ms", poly}, {"Bumpless + LP", ControllerKind("bumpless_lp")}, {"G_FF,avgA + LQG", lqg}};
}

std::vector<std::string> Fig11SemiactiveModes() { return {"passive_off", "passive_on", "clipped_optimal"}; }

scenario::Scenario Fig11Scenario(const scenario::Scenario& base, const Fig11Controller& c,
                                 const std::string& semiactive, const std::string& plant, double duration_s) {
  scenario::Scenario s = base;
  s.path.clear();
  s.sha256.clear();
  s.run.name = Slug(fmt::format("fig11 {} {} {}", plant == "ideal" ? kNumerical : c.name, semiactive, plant));
  s.run.duration_s = duration_s;
  s.controller = c.controller;
  s.plant.kind = ParseName(models::kPlantKindNames, plant, "plant");
  s.semiactive.mode = ParseName(control::kSemiactiveModeNames, semiactive, "semiactive");
  return s;
}

namespace {

/// Which controller and semiactive mode each spec runs.
struct Item {
  std::string controller, mode;
};

/// The specs: the numerical simulations first (they are the references), then the RTHS runs,
/// controller-major; `items` in the same order.
std::vector<RunSpec> Fig11Specs(const ReproduceOptions& opts, const scenario::Scenario& base, double duration,
                                std::vector<Item>* items) {
  std::vector<RunSpec> specs;
  for (const auto& mode : Fig11SemiactiveModes()) {
    Fig11Controller none{kNumerical, ControllerKind("none")};
    const fs::path dir = opts.out_dir / "runs" / Slug(fmt::format("numerical {}", mode));
    specs.push_back({fmt::format("Numerical / {}", mode), Fig11Scenario(base, none, mode, "ideal", duration), dir});
    items->push_back({kNumerical, mode});
  }
  for (const auto& c : Fig11Controllers()) {
    for (const auto& mode : Fig11SemiactiveModes()) {
      const fs::path dir = opts.out_dir / "runs" / Slug(fmt::format("{} {}", c.name, mode));
      specs.push_back({fmt::format("{} / {}", c.name, mode), Fig11Scenario(base, c, mode, opts.plant, duration), dir});
      items->push_back({c.name, mode});
    }
  }
  return specs;
}

/// The table: every run summarised from its log (its damper's signals into `traces`), its force
/// against the numerical run of its mode.
Fig11Result Fig11Table(const std::vector<RunSpec>& specs, const std::vector<Item>& items,
                       const std::vector<RunResult>& results, double dt, std::vector<Fig11Trace>* traces) {
  Fig11Result res;
  traces->assign(specs.size(), {});
  std::vector<Fig11Run> all;
  for (std::size_t j = 0; j < specs.size(); ++j) {
    if (results[j].steps == 0) {
      throw Error("fig11", fmt::format("{} did not run: {}", results[j].label, results[j].error));
    }
    all.push_back(Summarise(specs[j].dir, items[j].controller, items[j].mode, results[j], dt, &(*traces)[j]));
  }
  auto numerical_index = [&](const std::string& mode) {
    for (std::size_t j = 0; j < items.size(); ++j) {
      if (items[j].controller == kNumerical && items[j].mode == mode) return j;
    }
    return items.size();
  };
  for (std::size_t j = 0; j < all.size(); ++j) {
    const auto& ref = (*traces)[numerical_index(items[j].mode)].f_kN;
    const auto& f = (*traces)[j].f_kN;
    const std::size_t n = std::min(ref.size(), f.size());
    all[j].force_rths_vs_numerical_nrmse_pct =
        n > 0 ? signal::RmsErrorPercent(std::span(ref.data(), n), std::span(f.data(), n)) : 0.0;
    (items[j].controller == kNumerical ? res.numerical : res.runs).push_back(all[j]);
  }
  return res;
}

void WriteJson(const fs::path& file, const std::vector<Fig11Run>& runs) {
  nlohmann::json j;
  j["runs"] = nlohmann::json::array();
  for (const auto& r : runs) j["runs"].push_back(ToJson(r));
  std::ofstream out(file);
  if (!out) throw Error(file.string(), "cannot open for writing");
  out << j.dump(2) << "\n";
}

/// fig11_damper_<mode>.png: the damper's histories and loops, RTHS with each controller against
/// the numerical simulation.
Figure DamperFigure(const std::string& mode, const std::vector<Item>& items, const std::vector<Fig11Trace>& traces,
                    const ReproduceOptions& opts) {
  const std::size_t stride = opts.quick ? 2 : 4;
  Figure fig;
  fig.name = "fig11_damper_" + mode;
  fig.gnuplot = opts.gnuplot;
  fig.title = fmt::format("Fig. 11: damper at the first story, semiactive {}: RTHS with each controller on the {} "
                          "plant vs the numerical simulation (ideal tracking)",
                          mode, opts.plant);
  fig.columns = 2;
  fig.width_px = 1600;
  fig.panel_height_px = 420;
  Panel disp = MakePanel("Damper displacement", "Time [s]", "Displacement [mm]");
  Panel force = MakePanel("Damper force (one of 18)", "Time [s]", "Force [kN]");
  Panel fd = MakePanel("Force-displacement", "Displacement [mm]", "Force [kN]");
  Panel fv = MakePanel("Force-velocity", "Velocity [mm/s]", "Force [kN]");
  // One legend, beside the top right panel; the right column keeps the same margin.
  for (Panel* p : {&disp, &force, &fd, &fv}) p->key = "off";
  force.key = "outside right top";
  // RTHS first, the numerical reference last (dashed, on top).
  std::vector<std::size_t> order;
  for (std::size_t j = 0; j < items.size(); ++j) {
    if (items[j].mode == mode && items[j].controller != kNumerical) order.push_back(j);
  }
  for (std::size_t j = 0; j < items.size(); ++j) {
    if (items[j].mode == mode && items[j].controller == kNumerical) order.push_back(j);
  }
  for (std::size_t j : order) {
    const bool num = items[j].controller == kNumerical;
    const std::string title = num ? "Numerical (ideal)" : items[j].controller;
    const Series style = StyledSeries(title, ControllerStyle(items[j].controller));
    const auto& tr = traces[j];
    disp.series.push_back(Thin(style, tr.t, tr.y_mm, stride));
    force.series.push_back(Thin(style, tr.t, tr.f_kN, stride));
    fd.series.push_back(Thin(style, tr.y_mm, tr.f_kN, stride));
    fv.series.push_back(Thin(style, tr.v_mm_s, tr.f_kN, stride));
  }
  force.right_margin_chars = fv.right_margin_chars = io::KeyMarginChars({&force});
  fig.panels = {disp, force, fd, fv};
  return fig;
}

void WriteFigures(const Fig11Result& res, const std::vector<Item>& items, const std::vector<Fig11Trace>& traces,
                  const ReproduceOptions& opts) {
  if (!GnuplotAvailable(opts.gnuplot)) {
    if (opts.log) opts.log("fig11: gnuplot not found, no PNGs (apt-get install gnuplot-nox)");
    return;
  }
  for (const auto& mode : Fig11SemiactiveModes()) Plot(DamperFigure(mode, items, traces, opts), opts.out_dir);
  Figure stories = Fig11StoriesFigure(res);
  stories.gnuplot = opts.gnuplot;
  Plot(stories, opts.out_dir);
}

void WriteMarkdown(const Fig11Result& res, const ReproduceOptions& opts, std::size_t n_runs, double duration) {
  std::ofstream md(opts.out_dir / "fig11.md");
  md << "# Fig. 11: 9-story building, El Centro NS x 0.5, semiactive MR dampers\n\n"
     << fmt::format("Made by `rths reproduce fig11{} --plant {}`: {} runs of {:g} s in {:.0f} s wall time.\n\n",
                    opts.quick ? " --quick" : "", opts.plant, n_runs, duration, res.wall_s)
     << "| controller | semiactive | stopped | peak drift story 1 [mm] | max peak drift [mm] | max peak abs. "
        "acc. [mm/s^2] | damper peak force [kN] | damper peak disp. [mm] | force vs numerical [%] | "
        "accel. extrapolation err. [%] | velocity prediction err. [%] |\n"
     << "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto* set : {&res.numerical, &res.runs}) {
    for (const auto& r : *set) {
      md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", r.controller, r.semiactive,
                        r.stopped, FormatSig(r.peak_drift_mm[0], 4),
                        FormatSig(*std::max_element(r.peak_drift_mm.begin(), r.peak_drift_mm.end()), 4),
                        FormatSig(1000.0 * *std::max_element(r.peak_abs_accel_mps2.begin(), r.peak_abs_accel_mps2.end()), 4),
                        FormatSig(r.damper_peak_force_kN, 4), FormatSig(r.damper_peak_disp_mm, 4),
                        FormatSig(r.force_rths_vs_numerical_nrmse_pct, 3),
                        FormatSig(r.accel_extrapolation_rms_err_pct, 3), FormatSig(r.velocity_prediction_rms_err_pct, 3));
    }
  }
  md << "\n## The paper's statements, checked on these runs\n\n";
  for (const auto& c : res.claims) md << ClaimMarkdown(c);
}

}  // namespace

std::vector<Claim> CheckFig11Claims(const Fig11Result& res) {
  std::vector<Claim> claims;
  const std::string lqg = "G_FF,avgA + LQG";
  // (1) bounded under clipped-optimal switching
  Claim bounded{"(1) every compensated RTHS stays bounded under clipped-optimal switching (the paper's uncompensated "
                "one went unstable)",
                true, ""};
  // (2) FF + LQG closest to the numerical force
  Claim closest{"(2) under clipped-optimal control the damper force of " + lqg +
                    " is the closest to the numerical simulation's of the three compensators",
                true, ""};
  double lqg_err = std::numeric_limits<double>::quiet_NaN(), best_other = std::numeric_limits<double>::infinity();
  std::string best_name, errors;
  for (const auto& r : res.runs) {
    if (r.semiactive != "clipped_optimal") continue;
    const bool ok = r.stopped == "no" && std::isfinite(r.force_rths_vs_numerical_nrmse_pct);
    bounded.holds = bounded.holds && ok;
    bounded.detail += fmt::format("{}{}: {}", bounded.detail.empty() ? "" : "; ", r.controller,
                                  ok ? "bounded" : "stopped (" + r.stopped + ")");
    errors += fmt::format("{}{} {:.3g} %", errors.empty() ? "" : ", ", r.controller, r.force_rths_vs_numerical_nrmse_pct);
    if (r.controller == lqg) {
      lqg_err = r.force_rths_vs_numerical_nrmse_pct;
    } else if (r.force_rths_vs_numerical_nrmse_pct < best_other) {
      best_other = r.force_rths_vs_numerical_nrmse_pct;
      best_name = r.controller;
    }
  }
  closest.holds = lqg_err < best_other;
  closest.detail = "force error against the numerical simulation (Eq. 31): " + errors +
                   (closest.holds ? "" : fmt::format("; {} is closer", best_name));
  // (3) predictions at least as accurate as the paper's
  Claim predictions{"(3) the predicted acceleration (Eq. 20) and velocity (Eq. 21) are at least as accurate as the "
                    "paper's (1.81 %, 0.0061 %) in every RTHS run",
                    true, ""};
  double worst_a = 0, worst_v = 0;
  for (const auto& r : res.runs) {
    worst_a = std::max(worst_a, r.accel_extrapolation_rms_err_pct);
    worst_v = std::max(worst_v, r.velocity_prediction_rms_err_pct);
  }
  predictions.holds = worst_a <= 1.81 && worst_v <= 0.0061;
  predictions.detail = fmt::format("largest: Eq. 20 {:.3g} %, Eq. 21 {:.3g} %", worst_a, worst_v);
  claims = {bounded, closest, predictions};
  return claims;
}

Fig11Result ReproduceFig11(const ReproduceOptions& opts) {
  const auto t0 = std::chrono::steady_clock::now();
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  if (opts.plant != "ideal") RequirePlant(opts.plant, opts.out_dir);
  const fs::path base_file = io::FindSourceFile("scenarios/fig11_base.toml", opts.source_dir);
  const scenario::Scenario base = scenario::LoadScenario(base_file.string());
  const double duration = opts.quick ? kFig11QuickS : kFig11FullS;

  std::vector<Item> items;
  std::vector<RunSpec> specs = Fig11Specs(opts, base, duration, &items);
  const std::string intro = fmt::format(
      "fig11: {} lockstep runs of {:g} s (9 RTHS on the {} plant + 3 numerical), {} at a time (base {})",
      specs.size(), duration, opts.plant, opts.jobs, base_file.string());
  const auto results = RunStudyBatch(&specs, opts, intro, [&](std::size_t done, std::size_t total, const RunResult& r) {
    if (!opts.log) return;
    opts.log(fmt::format("  [{:2}/{}] {:<36} peak f {:7.2f} kN ({:.1f} s){}", done, total, r.label, r.peak_force_kN,
                         r.wall_s, r.ok ? "" : "  STOPPED: " + StoppedText(r)));
  });
  std::vector<Fig11Trace> traces;
  Fig11Result res = Fig11Table(specs, items, results, base.run.dt_s, &traces);
  WriteJson(opts.out_dir / "fig11_summary.json", res.runs);
  WriteJson(opts.out_dir / "fig11_numerical.json", res.numerical);
  WriteFigures(res, items, traces, opts);
  res.wall_s = SecondsSince(t0);
  res.claims = CheckFig11Claims(res);
  WriteMarkdown(res, opts, specs.size(), duration);
  return res;
}

}  // namespace rths::studies
