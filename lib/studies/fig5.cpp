// Fig. 5 (docs/experiments.md E6): the 200-kN MR damper model (Eqs. 32-39, Table 3) under a prescribed
// 25.4 mm, 1 Hz sine at six constant currents.
#include "studies/fig5.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"
#include "models/mr_damper.h"
#include "io/csv.h"
#include "io/plot.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::Series;
using io::Panel;
using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Plot;
using io::CsvWriter;

namespace {

struct Sine {
  double amplitude_mm = 25.4;
  double frequency_hz = 1.0;
};

void SineMotion(double t_s, void* ctx, double* x_mm, double* xdot_mm_s) {
  const auto* s = static_cast<const Sine*>(ctx);
  const double w = 2.0 * std::numbers::pi * s->frequency_hz;
  *x_mm = s->amplitude_mm * std::sin(w * t_s);
  *xdot_mm_s = s->amplitude_mm * w * std::cos(w * t_s);
}

struct Loop {
  std::vector<double> t_s, x_mm, v_mm_s, f_kN;
};

// Three cycles from rest at a constant current, sampled every dt_s.
Loop Simulate(double current_A, double dt_s) {
  Sine sine;
  models::MrDamperStepper stepper(models::MrDamperParams::Table3(), &SineMotion, &sine, 1e-8);
  models::MrDamperState state;
  Loop loop;
  const int n = static_cast<int>(std::lround(3.0 / sine.frequency_hz / dt_s));
  for (int k = 0; k <= n; ++k) {
    const double t = k * dt_s;
    double x, v;
    SineMotion(t, &sine, &x, &v);
    loop.t_s.push_back(t);
    loop.x_mm.push_back(x);
    loop.v_mm_s.push_back(v);
    loop.f_kN.push_back(stepper.ForceKn(t, current_A, state));
    if (k < n) stepper.Advance(t, t + dt_s, current_A, &state);
  }
  return loop;
}

}  // namespace

const std::vector<double>& Fig5ReferencePeaksKn() {
  static const std::vector<double> peaks{18.3, 77.9, 139.6, 166.8, 179.7, 187.0};
  return peaks;
}

namespace {

/// The table: the loops at every current and their peaks over cycles 2 and 3.
Fig5Result SimulateLoops(const ReproduceOptions& opts, double dt_s, std::vector<Loop>* loops) {
  Fig5Result res;
  res.current_A = {0.0, 0.5, 1.0, 1.5, 2.0, 2.5};
  res.paper_peak_kN = Fig5ReferencePeaksKn();
  for (double i : res.current_A) {
    loops->push_back(Simulate(i, dt_s));
    double peak = 0.0;
    const Loop& l = loops->back();
    for (std::size_t k = 0; k < l.t_s.size(); ++k) {
      if (l.t_s[k] >= 1.0) peak = std::max(peak, std::abs(l.f_kN[k]));  // cycles 2 and 3
    }
    res.ours_peak_kN.push_back(peak);
    if (opts.log) {
      const double ref = res.paper_peak_kN[res.ours_peak_kN.size() - 1];
      opts.log(fmt::format("  {:.1f} A: peak {:7.2f} kN (reference {:6.1f} kN, {:+.2f} %)", i, peak, ref,
                           100.0 * (peak / ref - 1.0)));
    }
  }
  return res;
}

void WriteCsvs(const Fig5Result& res, const std::vector<Loop>& loops, const fs::path& dir) {
  {
    CsvWriter csv(dir / "fig5_peaks.csv", {"current_A", "paper_peak_kN", "ours_peak_kN"});
    for (std::size_t j = 0; j < res.current_A.size(); ++j) {
      csv.Row({fmt::format("{:.1f}", res.current_A[j]), fmt::format("{:.1f}", res.paper_peak_kN[j]),
               fmt::format("{:.3f}", res.ours_peak_kN[j])});
    }
    csv.Close();
  }
  CsvWriter csv(dir / "fig5_loops.csv", {"current_A", "t_s", "x_mm", "v_mm_s", "F_kN"});
  for (std::size_t j = 0; j < loops.size(); ++j) {
    const Loop& l = loops[j];
    for (std::size_t k = 0; k < l.t_s.size(); ++k) {
      csv.Row({fmt::format("{:.1f}", res.current_A[j]), fmt::format("{:.4f}", l.t_s[k]),
               fmt::format("{:.6g}", l.x_mm[k]), fmt::format("{:.6g}", l.v_mm_s[k]), fmt::format("{:.6g}", l.f_kN[k])});
    }
  }
  csv.Close();
}

/// Force-time over the three cycles; the loops over cycles 2 and 3 (the start-up is left out).
Figure Fig5Figure(const Fig5Result& res, const std::vector<Loop>& loops) {
  Figure fig;
  fig.name = "fig5";
  fig.title = "Fig. 5: MR damper model (Eqs. 32-39, Table 3), 25.4 mm 1 Hz sine";
  fig.columns = 3;
  fig.width_px = 1500;
  fig.panel_height_px = 460;
  Panel ft = MakePanel("Force-time", "Time [s]", "Force [kN]");
  Panel fx = MakePanel("Force-displacement", "Displacement [mm]", "Force [kN]");
  Panel fv = MakePanel("Force-velocity", "Velocity [mm/s]", "Force [kN]");
  ft.key = fx.key = "off";
  fv.key = "top left";  // negative velocity, positive force: empty in every loop
  // io::ReadableColors() in an order that makes neighbouring currents (whose curves lie close
  // together) differ most in hue.
  const std::vector<std::string> colors = {"#666666", "#CC79A7", "#009E73", "#D55E00", "#0072B2", "#000000"};
  for (std::size_t j = 0; j < loops.size(); ++j) {
    const Loop& l = loops[j];
    const std::string name = fmt::format("{:.1f} A", res.current_A[j]);
    const std::string& color = colors[j % colors.size()];
    Series a = MakeSeries(name, color), b = MakeSeries(name, color), c = MakeSeries(name, color);
    for (std::size_t k = 0; k < l.t_s.size(); k += 2) {
      a.x.push_back(l.t_s[k]);
      a.y.push_back(l.f_kN[k]);
      if (l.t_s[k] < 1.0) continue;
      b.x.push_back(l.x_mm[k]);
      b.y.push_back(l.f_kN[k]);
      c.x.push_back(l.v_mm_s[k]);
      c.y.push_back(l.f_kN[k]);
    }
    ft.series.push_back(a);
    fx.series.push_back(b);
    fv.series.push_back(c);
  }
  fig.panels = {ft, fx, fv};
  return fig;
}

}  // namespace

Fig5Result ReproduceFig5(const ReproduceOptions& opts) {
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  const double dt_s = 0.0005;  // 2 kHz, the paper's rate
  std::vector<Loop> loops;
  Fig5Result res = SimulateLoops(opts, dt_s, &loops);
  double worst = 0.0;
  for (std::size_t i = 0; i < res.current_A.size(); ++i) {
    worst = std::max(worst, std::abs(res.ours_peak_kN[i] / res.paper_peak_kN[i] - 1.0));
  }
  res.claims = {{"E6: the six peak forces within 2 % of the reference", worst <= 0.02,
                 fmt::format("largest peak difference {:.2f} %", 100 * worst)}};
  WriteCsvs(res, loops, opts.out_dir);
  Figure fig = Fig5Figure(res, loops);
  fig.gnuplot = opts.gnuplot;
  Plot(fig, opts.out_dir);
  return res;
}

}  // namespace rths::studies
