// `rths reproduce nonlinear`: the critical delay per integrator (studies/nonlinear_delay.h,
// docs/reproduce_nonlinear.md).
#include "studies/nonlinear_delay.h"

#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "core/error.h"
#include "io/csv.h"
#include "io/source_tree.h"
#include "signal/history.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::FormatSig;

NonlinearDelaySettings NonlinearDelayDefaults(bool quick) {
  NonlinearDelaySettings s;
  if (quick) {
    s.record_s = 8.0;
    s.tail_s = 8.0;
    s.search.resolution_s = 5e-5;
  } else {
    s.record_s = 0.0;
    s.tail_s = 20.0;
    s.search.resolution_s = 1e-5;
  }
  return s;
}

DelayLoop ReferenceDelayLoop(const scenario::Scenario& ref, bool yielding, const models::IntegratorConfig& integrator,
                             DelayCompensation compensation, double record_s, double tail_s) {
  const auto& st = ref.structure;
  DelayLoop loop;
  loop.sdof.mass_kg = st.mass_kg;
  loop.sdof.frequency_hz = st.frequency_hz;
  loop.sdof.damping_ratio = st.damping_ratio;
  loop.sdof.physical_fraction = kNonlinearPhysicalFraction;
  loop.sdof.spring = yielding ? st.spring : models::SpringParams{};
  loop.integrator = integrator;
  loop.dt_s = ref.run.dt_s;
  loop.tail_s = tail_s;
  loop.compensation = compensation;
  const double len = record_s > 0.0 ? record_s : ref.run.duration_s;
  loop.ground_mm_s2 =
      signal::MakeSignal(st.ground, loop.dt_s, static_cast<std::size_t>(std::llround(len / loop.dt_s)));
  return loop;
}

std::vector<models::IntegratorConfig> NonlinearDelayIntegrators() {
  std::vector<models::IntegratorConfig> v;
  for (auto k : {models::IntegratorKind::kCentralDifference, models::IntegratorKind::kCr,
                 models::IntegratorKind::kAlphaOs, models::IntegratorKind::kNewmarkImplicit}) {
    models::IntegratorConfig c;
    c.kind = k;
    v.push_back(c);
  }
  return v;
}

const std::vector<NonlinearDelayColumn>& NonlinearDelayColumns() {
  static const std::vector<NonlinearDelayColumn> columns = {
      {"none", DelayCompensation::kNone, DelayCriterion::kDecay, &NonlinearDelayRow::none},
      {"none_divergence", DelayCompensation::kNone, DelayCriterion::kDivergence, &NonlinearDelayRow::none_divergence},
      {"poly3", DelayCompensation::kPoly3, DelayCriterion::kDecay, &NonlinearDelayRow::poly3},
      {"lead", DelayCompensation::kLead, DelayCriterion::kDecay, &NonlinearDelayRow::lead},
      {"ff", DelayCompensation::kFf, DelayCriterion::kDecay, &NonlinearDelayRow::ff},
  };
  return columns;
}

NonlinearDelayResult RunNonlinearDelay(const scenario::Scenario& ref, const NonlinearDelaySettings& settings, int jobs,
                                       const std::function<void(std::string_view)>& log) {
  const auto t0 = std::chrono::steady_clock::now();
  NonlinearDelayResult res;
  res.settings = settings;
  res.dt_s = ref.run.dt_s;
  // One job per (integrator, structure, column); rows integrator-major, linear first.
  struct Job {
    std::size_t row;
    const NonlinearDelayColumn* column;
    DelayLoop loop;
  };
  std::vector<Job> work;
  for (const auto& integ : NonlinearDelayIntegrators()) {
    for (bool yielding : {false, true}) {
      NonlinearDelayRow row;
      row.integrator = std::string(NameOf(models::kIntegratorKindNames, integ.kind));
      row.yielding = yielding;
      for (const auto& col : NonlinearDelayColumns()) {
        work.push_back({res.rows.size(), &col,
                        ReferenceDelayLoop(ref, yielding, integ, col.compensation, settings.record_s, settings.tail_s)});
      }
      const SplitSdof& s = work.back().loop.sdof;
      row.analytic = ContinuousDelayMargin(s.Mass_kN_s2_per_mm(), s.Damping_kN_s_per_mm(),
                                           s.NumericalStiffness_kN_per_mm(), s.PhysicalStiffness_kN_per_mm());
      if (!yielding) res.sdof = s;
      else res.spring = s.spring;
      res.rows.push_back(row);
    }
  }
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  std::vector<std::string> errors;
  auto worker = [&] {
    for (std::size_t i = next++; i < work.size(); i = next++) {
      const Job& j = work[i];
      DelaySearch search = settings.search;
      search.criterion = j.column->criterion;
      try {
        const CriticalDelay cd = FindCriticalDelay(j.loop, search);
        std::lock_guard<std::mutex> lock(mu);
        NonlinearDelayRow& row = res.rows[j.row];
        row.*(j.column->result) = cd;
        if (log) {
          log(fmt::format("  {:<18} {:<9} {:<15} tau_cr {} ms ({} runs)", row.integrator,
                          row.yielding ? "yielding" : "linear", j.column->name,
                          cd.found ? FormatSig(1e3 * cd.tau_s, 4) : "> " + FormatSig(1e3 * cd.tau_s, 3), cd.runs));
        }
      } catch (const Error& e) {
        std::lock_guard<std::mutex> lock(mu);
        errors.push_back(e.what());
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < std::max(1, jobs); ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (!errors.empty()) throw Error("nonlinear", errors.front());
  res.wall_s = SecondsSince(t0);
  return res;
}

namespace {

/// tau_cr [ms] as a table cell: 4 digits, "> max" when not found.
std::string TauCell(const CriticalDelay& c) {
  return c.found ? FormatSig(1e3 * c.tau_s, 4) : "> " + FormatSig(1e3 * c.tau_s, 3);
}

void WriteCsv(const NonlinearDelayResult& r, const fs::path& dir) {
  io::CsvWriter csv(dir / "critical_delay.csv",
                    {"integrator", "structure", "column", "tau_cr_ms", "found", "stable_ms", "unstable_ms",
                     "verdict", "runs", "delay_free_peak_mm", "delay_free_ductility", "analytic_ms",
                     "negative_damping_ms"});
  for (const auto& row : r.rows) {
    for (const auto& col : NonlinearDelayColumns()) {
      const CriticalDelay& c = row.*col.result;
      csv.Row({row.integrator, row.yielding ? "yielding" : "linear", col.name, FormatSig(1e3 * c.tau_s, 6),
               c.found ? "yes" : "no", FormatSig(1e3 * c.stable_s, 6), c.found ? FormatSig(1e3 * c.unstable_s, 6) : "",
               c.verdict, std::to_string(c.runs), FormatSig(c.delay_free_peak_mm, 4),
               row.yielding ? FormatSig(c.delay_free_ductility, 3) : "",
               row.yielding || !row.analytic.exists ? "" : FormatSig(1e3 * row.analytic.tau_s, 6),
               row.yielding ? "" : FormatSig(1e3 * row.analytic.negative_damping_s, 6)});
    }
  }
  csv.Close();
}

void WriteMarkdown(const NonlinearDelayResult& r, const ReproduceOptions& opts) {
  std::ofstream md(opts.out_dir / "critical_delay.md");
  const SplitSdof& s = r.sdof;
  const auto& set = r.settings;
  md << "# Critical delay of the RTHS loop per integrator\n\n"
     << fmt::format("Made by `rths reproduce nonlinear{}` in {:.0f} s wall time ({} searches at a time), {}.\n\n",
                    opts.quick ? " --quick" : "", r.wall_s, opts.jobs, UtcStamp())
     << fmt::format("SDOF of scenarios/nonlinear/reference_sdof.toml: m = {:g} kg, f = {:g} Hz, zeta = {:g} "
                    "(c = {} kN s/mm), k = {} kN/mm; numerical: m, c and a spring of {} kN/mm (linear, or "
                    "Bouc-Wen alpha = {:g}, x_y = {:g} mm, n = {:g}); physical: a linear spring k_e = {} kN/mm "
                    "({:g} % of k). Actuator: a pure delay. El Centro NS, first {:g} s, then {:g} s of free "
                    "vibration; dt = {:g} ms. Bisection to {:g} ms.\n\n",
                    s.mass_kg, s.frequency_hz, s.damping_ratio, FormatSig(s.Damping_kN_s_per_mm(), 4),
                    FormatSig(s.TotalStiffness_kN_per_mm(), 4), FormatSig(s.NumericalStiffness_kN_per_mm(), 4),
                    r.spring.alpha, r.spring.x_y_mm, r.spring.n, FormatSig(s.PhysicalStiffness_kN_per_mm(), 4),
                    100 * s.physical_fraction, set.record_s, set.tail_s, 1e3 * r.dt_s,
                    1e3 * set.search.resolution_s);
  md << "Critical delay tau_cr [ms]: the midpoint of the last bisection bracket; \"> x\": stable up to x ms. "
        "none: no compensation, unstable once the free vibration after the record stops decaying (or it "
        "diverges); none, diverges: the smallest delay at which the response exceeds "
     << FormatSig(set.search.divergence_factor, 3)
     << " x the delay-free peak within record and tail; poly3: third-order polynomial extrapolation over "
        "tau (Horiuchi et al. 1996); lead: the lead compensator over tau (T_p = 0.5 ms); ff: the model-inverse "
        "feedforward of the third-order Taylor model of the delay (TaylorDelayModel); the compensated columns by "
        "the decay criterion, each designed for the delay it faces. Analytic: the exact delay margin of the "
        "continuous linear loop (Wallace et al. 2005); c / k_e: the negative-damping estimate (Horiuchi et al. "
        "1999). Ductility: the numerical spring's peak drift over x_y without delay.\n\n"
     << "| integrator | structure | none | none, diverges | poly3 | lead | ff | analytic | c / k_e | delay-free peak [mm] | ductility |\n"
     << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& row : r.rows) {
    md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", row.integrator,
                      row.yielding ? "yielding" : "linear", TauCell(row.none), TauCell(row.none_divergence),
                      TauCell(row.poly3), TauCell(row.lead), TauCell(row.ff),
                      row.yielding ? "" : FormatSig(1e3 * row.analytic.tau_s, 4),
                      row.yielding ? "" : FormatSig(1e3 * row.analytic.negative_damping_s, 4),
                      FormatSig(row.none.delay_free_peak_mm, 3),
                      row.yielding ? FormatSig(row.none.delay_free_ductility, 3) : "");
  }
  md << "\nEach search's bracket, the verdict of its smallest unstable delay (\"diverged\", \"does not decay\") "
        "and the runs it took: critical_delay.csv.\n";
}

}  // namespace

io::Figure NonlinearDelayFigure(const NonlinearDelayResult& r, bool quick) {
  io::Figure fig;
  fig.name = "critical_delay";
  fig.title = fmt::format("Critical delay of the RTHS loop, SDOF 5 Hz, k_e = {:g} % of k{}",
                          100 * r.sdof.physical_fraction, quick ? " (--quick)" : "");
  fig.columns = 2;
  fig.width_px = 1200;
  fig.panel_height_px = 420;
  // ff is left out: it falls on poly3 (critical_delay.md has both).
  struct Style {
    const char* column;
    const char* title;
    const char* color;
    const char* with;
  };
  const std::array<Style, 4> styles = {{{"none", "none (stops decaying)", "#0072B2", "points pt 7 ps 1.6"},
                                        {"none_divergence", "none (diverges)", "#666666", "points pt 6 ps 1.6"},
                                        {"poly3", "poly3 over tau", "#D55E00", "points pt 5 ps 1.5"},
                                        {"lead", "lead over tau", "#009E73", "points pt 9 ps 1.8"}}};
  for (bool yielding : {false, true}) {
    io::Panel p = io::MakePanel(yielding ? "Yielding (Bouc-Wen) numerical spring" : "Linear numerical spring", "",
                                "Critical delay tau_cr [ms]");
    p.log_y = true;
    p.key = "top left";
    p.margin_fraction = 0.08;
    std::vector<std::string> names;
    for (const auto& row : r.rows) {
      if (row.yielding == yielding) names.push_back(row.integrator);
    }
    for (std::size_t i = 0; i < names.size(); ++i) p.x_tics.emplace_back(static_cast<double>(i + 1), names[i]);
    p.x_range = std::make_pair(0.5, names.size() + 0.5);
    for (std::size_t c = 0; c < styles.size(); ++c) {
      io::Series s = io::MakeSeries(styles[c].title, styles[c].color);
      s.with = styles[c].with;
      const NonlinearDelayColumn* col = nullptr;
      for (const auto& k : NonlinearDelayColumns()) {
        if (std::string(k.name) == styles[c].column) col = &k;
      }
      double x = 1.0;
      for (const auto& row : r.rows) {
        if (row.yielding != yielding) continue;
        const CriticalDelay& cd = row.*(col->result);
        s.x.push_back(x + (static_cast<double>(c) - 1.5) * 0.1);
        s.y.push_back(cd.found ? 1e3 * cd.tau_s : std::nan(""));
        x += 1.0;
      }
      p.series.push_back(s);
    }
    if (!yielding && !r.rows.empty() && r.rows.front().analytic.exists) {
      io::Series a = io::MakeSeries("analytic (continuous)", "#000000", 2);
      a.x = {0.5, names.size() + 0.5};
      a.y = {1e3 * r.rows.front().analytic.tau_s, 1e3 * r.rows.front().analytic.tau_s};
      p.series.push_back(a);
    }
    fig.panels.push_back(p);
  }
  return fig;
}

NonlinearDelayResult ReproduceNonlinear(const ReproduceOptions& opts) {
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  const fs::path file = io::FindSourceFile("scenarios/nonlinear/reference_sdof.toml", opts.source_dir);
  const scenario::Scenario ref = scenario::LoadScenario(file.string());
  const NonlinearDelaySettings settings = NonlinearDelayDefaults(opts.quick);
  if (opts.log) {
    opts.log(fmt::format("nonlinear: critical delays of 4 integrators x 2 structures x {} columns from {}",
                         NonlinearDelayColumns().size(), file.string()));
  }
  NonlinearDelayResult res = RunNonlinearDelay(ref, settings, opts.jobs, opts.log);
  if (res.settings.record_s <= 0.0) res.settings.record_s = ref.run.duration_s;
  WriteCsv(res, opts.out_dir);
  if (io::GnuplotAvailable(opts.gnuplot)) {
    io::Figure fig = NonlinearDelayFigure(res, opts.quick);
    fig.gnuplot = opts.gnuplot;
    io::Plot(fig, opts.out_dir);
  } else if (opts.log) {
    opts.log("nonlinear: gnuplot not found, no critical_delay.png (apt-get install gnuplot-nox)");
  }
  WriteMarkdown(res, opts);
  double worst = 0.0;
  for (const auto& row : res.rows) {
    // newmark_implicit holds the force one sample late: its margin is one dt shorter (the docs say why).
    if (!row.yielding && row.integrator != "newmark_implicit" && row.none.found) {
      worst = std::max(worst, std::abs(row.none.tau_s / row.analytic.tau_s - 1.0));
    }
  }
  res.claims = {{"linear rows (central_difference, cr, alpha_os) within 2 % of the closed-form delay margin",
                 worst <= 0.02, fmt::format("largest difference {:.2f} %", 100 * worst)}};
  return res;
}

}  // namespace rths::studies
