// Frequency-domain reproductions: Fig. 6 (E1, identification of G_yu) and Figs. 7-8 (E2, G_yr
// through each controller of Table 1). Each measurement is a lockstep run with a predefined
// BLWN 0-50 Hz desired displacement; spectra by Welch / H1 (signal/spectral.h), fits by
// ident/fit.h.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <ctime>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"
#include "ident/identify.h"
#include "io/csv.h"
#include "io/plot.h"
#include "report/figures.h"
#include "report/reproduce.h"

namespace rths::report {

namespace fs = std::filesystem;
using io::Series;
using io::Panel;
using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Plot;
using io::CsvWriter;
using io::FormatSig;

namespace {

constexpr double kBandHz = 50.0;        // E1/E2: BLWN 0-50 Hz
constexpr double kRmsMm = 0.254;        // RMS 0.254 mm
constexpr double kFullS = 60.0;         // record length
constexpr double kQuickS = 16.0;        // --quick
constexpr double kTaperS = 0.5;
constexpr double kFitLoHz = 0.5, kFitHiHz = 40.0;  // the paper: models accurate up to 40 Hz
constexpr double kPlotMaxHz = 50.0;
constexpr double kDt = 0.0005;

std::string Sig(double v) { return std::isfinite(v) ? fmt::format("{:#.4g}", v) : FormatSig(v); }

// Runs the specs (preflight first), logging progress; throws if any failed.
std::vector<RunResult> RunAll(std::vector<RunSpec> specs, const ReproduceOptions& opts, const std::string& what) {
  Preflight(&specs, opts.overrides, opts.log);
  if (opts.log) {
    opts.log(fmt::format("{}: {} lockstep runs on the {} plant, {} at a time", what, specs.size(), opts.plant, opts.jobs));
  }
  const auto results = RunBatch(specs, opts.jobs, opts.progress, [&](std::size_t done, std::size_t total, const RunResult& r) {
    if (!opts.log) return;
    opts.log(r.ok ? fmt::format("  [{:2}/{}] {:<28} done ({:.1f} s)", done, total, r.label, r.wall_s)
                  : fmt::format("  [{:2}/{}] {:<28} FAILED: {}", done, total, r.label, r.error));
  });
  std::string failed;
  for (const auto& r : results) {
    if (!r.ok) failed += fmt::format("\n  {}: {}", r.label, r.error);
  }
  if (!failed.empty()) throw Error(what, "runs failed (their folders are under runs/):" + failed);
  return results;
}

// Three stacked panels (magnitude, phase, time lag) for a set of curves: `solid` in their
// controller's style (report/figures.h; `proposed` drawn prominent, other names in palette
// order), then `styled` as given. One legend, beside the magnitude panel; the same margins in
// all three panels so their frequency axes line up.
Figure BodeFigure(const std::string& name, const std::string& title, const std::vector<BodeCurve>& solid,
                  const std::vector<std::pair<BodeCurve, Series>>& styled, const std::string& proposed = "") {
  Figure fig;
  fig.name = name;
  fig.title = title;
  fig.width_px = 1200;
  fig.panel_height_px = 330;
  Panel mag = MakePanel("", "Frequency [Hz]", "Magnitude [mm/mm]");
  Panel ph = MakePanel("", "Frequency [Hz]", "Phase [deg]");
  Panel lag = MakePanel("", "Frequency [Hz]", "Time lag [ms]");
  for (Panel* p : {&mag, &ph, &lag}) {
    p->x_range = std::make_pair(0.0, kPlotMaxHz);
    p->left_margin_chars = 10;
    p->key = "off";
  }
  mag.key = "outside right top";
  auto add = [&](const BodeCurve& c, Series style) {
    Series m = style, p = style, l = style;
    m.x = p.x = l.x = c.f_hz;
    m.y = c.magnitude;
    p.y = c.phase_deg;
    l.y = c.lag_ms;
    mag.series.push_back(m);
    ph.series.push_back(p);
    lag.series.push_back(l);
  };
  for (std::size_t i = 0; i < solid.size(); ++i) {
    const BodeCurve& c = solid[i];
    add(c, StyledSeries(c.name, ControllerStyle(c.name, !proposed.empty() && c.name == proposed, i)));
  }
  for (const auto& [c, style] : styled) add(c, style);
  // Time lag: the range of the curves from 2 Hz up. Below, -phase / (2 pi f) divides the
  // estimate's phase noise by a small f and would squeeze the rest into a few pixels.
  double lo = 1e300, hi = -1e300;
  for (const auto& s : lag.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (s.x[i] >= 2.0 && std::isfinite(s.y[i])) lo = std::min(lo, s.y[i]), hi = std::max(hi, s.y[i]);
    }
  }
  if (lo <= hi) {
    const double pad = std::max(0.5, 0.1 * (hi - lo));
    lag.y_range = std::make_pair(std::floor(lo - pad), std::ceil(hi + pad));
  }
  const int key_margin = io::KeyMarginChars({&mag});
  for (Panel* p : {&mag, &ph, &lag}) p->right_margin_chars = key_margin;
  fig.panels = {mag, ph, lag};
  return fig;
}

void WriteCurvesCsv(const fs::path& file, const std::string& key_column, const std::vector<BodeCurve>& curves) {
  CsvWriter csv(file, {key_column, "f_hz", "magnitude", "phase_deg", "time_lag_ms", "coherence"});
  for (const auto& c : curves) {
    for (std::size_t i = 0; i < c.f_hz.size(); ++i) {
      csv.Row({c.name, fmt::format("{:.6g}", c.f_hz[i]), fmt::format("{:.6g}", c.magnitude[i]),
               fmt::format("{:.6g}", c.phase_deg[i]), fmt::format("{:.6g}", c.lag_ms[i]),
               fmt::format("{:.6g}", c.coherence[i])});
    }
  }
  csv.Close();
}

// Values of a curve over [lo, hi] Hz.
template <typename F>
void Over(const BodeCurve& c, double lo, double hi, F f) {
  for (std::size_t i = 0; i < c.f_hz.size(); ++i) {
    if (c.f_hz[i] >= lo && c.f_hz[i] <= hi) f(i);
  }
}
// Linear interpolation of a curve's column at f.
double At(const BodeCurve& c, const std::vector<double>& col, double f) {
  for (std::size_t i = 1; i < c.f_hz.size(); ++i) {
    if (c.f_hz[i] >= f) {
      const double w = (f - c.f_hz[i - 1]) / (c.f_hz[i] - c.f_hz[i - 1]);
      return col[i - 1] + w * (col[i] - col[i - 1]);
    }
  }
  return std::nan("");
}

}  // namespace

BodeCurve BodeFromEstimate(const std::string& name, const signal::FrequencyResponseEstimate& est, double f_max_hz) {
  BodeCurve c;
  c.name = name;
  std::vector<std::complex<double>> h;
  for (std::size_t i = 1; i < est.f_hz.size() && est.f_hz[i] <= f_max_hz + 1e-9; ++i) {
    c.f_hz.push_back(est.f_hz[i]);
    h.push_back(est.h[i]);
    c.coherence.push_back(est.coherence[i]);
  }
  const std::vector<double> phase = signal::UnwrapPhase(h);
  for (std::size_t i = 0; i < h.size(); ++i) {
    c.magnitude.push_back(std::abs(h[i]));
    c.phase_deg.push_back(phase[i] * 180.0 / std::numbers::pi);
    c.lag_ms.push_back(-phase[i] / (2.0 * std::numbers::pi * c.f_hz[i]) * 1e3);
  }
  return c;
}

BodeCurve BodeFromModel(const std::string& name, const ident::PoleModel& model, const std::vector<double>& f_hz,
                        double zoh_dt_s) {
  BodeCurve c;
  c.name = name;
  c.f_hz = f_hz;
  std::vector<std::complex<double>> h;
  if (zoh_dt_s > 0.0) {
    const ident::ZohModel d = ident::Discretise(model, zoh_dt_s);
    for (double f : f_hz) h.push_back(ident::ZohResponse(d, f));
  } else {
    for (double f : f_hz) h.push_back(model.Response(f));
  }
  const std::vector<double> phase = signal::UnwrapPhase(h);
  for (std::size_t i = 0; i < h.size(); ++i) {
    c.magnitude.push_back(std::abs(h[i]));
    c.phase_deg.push_back(phase[i] * 180.0 / std::numbers::pi);
    c.lag_ms.push_back(-phase[i] / (2.0 * std::numbers::pi * f_hz[i]) * 1e3);
    c.coherence.push_back(1.0);
  }
  return c;
}

signal::SignalSpec FrequencyExcitation() {
  signal::SignalSpec spec;
  spec.kind = signal::SignalKind::kBlwn;
  spec.band_hz = kBandHz;
  spec.rms = kRmsMm;
  spec.seed = 1;
  spec.discard_s = 2.0;
  spec.taper_s = kTaperS;
  return spec;
}

scenario::Scenario FrequencyScenario(const std::string& condition, const control::ControllerConfig& controller,
                                     const std::string& plant, double duration_s) {
  if (condition != "0.0A" && condition != "2.5A") {
    throw Error("FrequencyScenario", fmt::format("condition '{}' (allowed: 0.0A, 2.5A)", condition));
  }
  scenario::Scenario s;
  s.run.name = "freq";
  s.run.dt_s = kDt;
  s.run.duration_s = duration_s;
  s.structure.mode = models::StructureMode::kPredefined;
  s.structure.derivatives = models::Derivatives::kExtrapolated;
  s.structure.desired = FrequencyExcitation();
  s.controller = controller;
  s.plant.kind = ParseName(models::kPlantKindNames, plant, "--plant");
  s.plant.actuator = models::ServoPreset(condition);
  s.plant.specimen = models::Specimen::kMrDamper;
  s.semiactive.mode = condition == "0.0A" ? control::SemiactiveMode::kPassiveOff : control::SemiactiveMode::kPassiveOn;
  s.semiactive.max_current_A = 2.5;
  return s;
}

// --- Fig. 6 --------------------------------------------------------------------------------

Fig6Result ReproduceFig6(const ReproduceOptions& opts) {
  PrepareOutDir(opts.out_dir);
  RequirePlant(opts.plant, opts.out_dir);
  const double duration = opts.quick ? kQuickS : kFullS;
  const std::vector<std::string> conditions{"0.0A", "2.5A"};
  std::vector<RunSpec> specs;
  for (const auto& cond : conditions) {
    control::ControllerConfig none;
    none.kind = control::ControllerKind::kNone;
    auto s = FrequencyScenario(cond, none, opts.plant, duration);
    s.run.name = Slug("fig6 " + cond);
    specs.push_back({fmt::format("fig6 {} G_yu", cond), s, opts.out_dir / "runs" / Slug("gyu " + cond)});
  }
  const auto results = RunAll(specs, opts, "fig6");

  Fig6Result res;
  res.tolerance_pct = opts.plant == "linear" ? 3.0 : 8.0;
  ident::IdentifyOptions io;
  io.fit.poles = 3;
  io.fit.band_lo_hz = kFitLoHz;
  io.fit.band_hi_hz = kFitHiHz;
  io.fit.zoh_dt_s = kDt;  // the plant holds u over each step: fit the model whose ZOH gives the data
  std::vector<ident::IdentifyResult> ids;
  for (std::size_t j = 0; j < conditions.size(); ++j) {
    const Trace t = ReadTrace(results[j].dir);
    ids.push_back(ident::Identify(t.u_mm, t.y_mm, kDt, io));
    res.measured.push_back(BodeFromEstimate(conditions[j] == "0.0A" ? "0.0 A" : "2.5 A", ids.back().frf, kPlotMaxHz));
    Fig6Model m;
    m.condition = conditions[j];
    m.paper = models::ServoPreset(conditions[j]);
    m.fit = ids.back().fit;
    res.models.push_back(m);
    if (opts.log) opts.log(fmt::format("fig6 {}:\n{}", conditions[j], ids.back().fit.Report()));
  }
  // The average condition, as the paper made Eq. 30: the mean of the two measured responses.
  {
    const auto& a = ids[0].frf;
    const auto& b = ids[1].frf;
    if (a.f_hz.size() != b.f_hz.size()) throw Error("fig6", "the two estimates are on different grids");
    std::vector<std::complex<double>> h(a.h.size());
    std::vector<double> coh(a.h.size());
    double max_uu = 0.0;
    for (std::size_t i = 0; i < a.f_hz.size(); ++i) {
      if (a.f_hz[i] >= kFitLoHz && a.f_hz[i] <= kFitHiHz) max_uu = std::max(max_uu, std::min(ids[0].s_uu[i], ids[1].s_uu[i]));
    }
    for (std::size_t i = 0; i < h.size(); ++i) {
      h[i] = 0.5 * (a.h[i] + b.h[i]);
      const bool excited = std::min(ids[0].s_uu[i], ids[1].s_uu[i]) >= io.min_excitation * max_uu;
      coh[i] = excited ? std::min(a.coherence[i], b.coherence[i]) : 0.0;
    }
    Fig6Model m;
    m.condition = "avg";
    m.paper = models::ServoPreset("avg");
    m.fit = ident::FitPoleModel(a.f_hz, h, coh, io.fit);
    res.models.push_back(m);
  }
  for (auto& m : res.models) {
    const auto ours = m.fit.model.ToServoModel3();
    for (auto [p, o] : {std::pair{m.paper.K, ours.K}, {m.paper.p, ours.p}, {m.paper.b, ours.b}, {m.paper.c, ours.c}}) {
      m.max_diff_pct = std::max(m.max_diff_pct, 100.0 * std::abs(o / p - 1.0));
    }
  }
  res.verdict.text = fmt::format("E1: the 3-pole fits recover K, p, b, c of Eqs. 28 and 29 within {:g} % ({} plant)",
                                 res.tolerance_pct, opts.plant);
  res.verdict.holds = res.models[0].max_diff_pct <= res.tolerance_pct && res.models[1].max_diff_pct <= res.tolerance_pct;
  res.verdict.detail = fmt::format("largest parameter difference: 0.0 A {:.2f} %, 2.5 A {:.2f} % (average "
                                   "condition against Eq. 30: {:.2f} %)",
                                   res.models[0].max_diff_pct, res.models[1].max_diff_pct, res.models[2].max_diff_pct);

  // Files.
  WriteCurvesCsv(opts.out_dir / "fig6.csv", "condition", res.measured);
  {
    CsvWriter csv(opts.out_dir / "fig6_models.csv", {"condition", "parameter", "paper", "ours", "diff_pct"});
    for (const auto& m : res.models) {
      const auto ours = m.fit.model.ToServoModel3();
      const std::pair<const char*, std::pair<double, double>> rows[] = {
          {"K", {m.paper.K, ours.K}}, {"p", {m.paper.p, ours.p}}, {"b", {m.paper.b, ours.b}}, {"c", {m.paper.c, ours.c}}};
      for (const auto& [name, v] : rows) {
        csv.Row({m.condition, name, fmt::format("{:.6g}", v.first), fmt::format("{:.6g}", v.second),
                 fmt::format("{:.3f}", 100.0 * (v.second / v.first - 1.0))});
      }
    }
    csv.Close();
  }
  std::vector<std::pair<BodeCurve, Series>> overlays;
  for (std::size_t j = 0; j < 2; ++j) {
    overlays.push_back({BodeFromModel("fitted 3-pole models", res.models[j].fit.model, res.measured[j].f_hz, kDt),
                        MakeSeries(j == 0 ? "fitted 3-pole models" : "", "black", 2)});
  }
  for (std::size_t j = 0; j < 2; ++j) {
    Series paper = MakeSeries(j == 0 ? "Eqs. 28-29 (paper)" : "", "#666666", 3);
    paper.width = 2.0;  // dotted: a little wider to read as a line
    overlays.push_back({BodeFromModel("Eqs. 28-29 (paper)",
                                      ident::PoleModel::FromServoModel3(res.models[j].paper), res.measured[j].f_hz, kDt),
                        paper});
  }
  Figure fig = BodeFigure(
      "fig6", fmt::format("Fig. 6: measured G_yu ({} plant, no controller) with fitted models (ZOH at 2 kHz)", opts.plant),
      res.measured, overlays);
  fig.gnuplot = opts.gnuplot;
  Plot(fig, opts.out_dir);
  {
    std::ofstream md(opts.out_dir / "fig6.md");
    md << "# Fig. 6: identified servohydraulic models\n\n"
       << fmt::format("Made by `rths reproduce fig6{} --plant {}` on {}.\n\n", opts.quick ? " --quick" : "", opts.plant, UtcStamp())
       << fmt::format("BLWN 0-50 Hz, RMS {} mm, {:g} s, commanded with no controller (u = r) at 0.0 A and 2.5 A; "
                      "G_yu by H1 (Welch, Hann, 50 % overlap, {} segments of {:.3g} s); "
                      "K / ((s + p)(s^2 + b s + c)) fitted over {:g}-{:g} Hz as the model whose zero-order hold at "
                      "2 kHz gives the data.\n\n",
                      kRmsMm, duration, ids[0].frf.segments, ids[0].segment_length * kDt, kFitLoHz, kFitHiHz)
       << "| condition | parameter | paper | ours | difference |\n|---|---|---:|---:|---:|\n";
    for (const auto& m : res.models) {
      const auto ours = m.fit.model.ToServoModel3();
      const std::pair<const char*, std::pair<double, double>> rows[] = {
          {"K", {m.paper.K, ours.K}}, {"p", {m.paper.p, ours.p}}, {"b", {m.paper.b, ours.b}}, {"c", {m.paper.c, ours.c}}};
      for (const auto& [name, v] : rows) {
        md << fmt::format("| {} | {} | {} | {} | {:+.2f} % |\n", m.condition, name, Sig(v.first), Sig(v.second),
                          100.0 * (v.second / v.first - 1.0));
      }
    }
    md << fmt::format("\n**{}** {}.  \n{}\n", res.verdict.holds ? "Holds:" : "Does not hold:", res.verdict.text,
                      res.verdict.detail);
    md << fmt::format("\nFit quality over {:g}-{:g} Hz (our fit against our measured response), and how far our measured "
                      "response is from the paper's model (ZOH at 2 kHz) over the same band. Three-pole parameters trade "
                      "off against each other: a response a few percent away can move K, b, c by tens of percent.\n\n"
                      "| condition | fit: max magnitude error | fit: max phase error | DC gain | DC lag | measured vs "
                      "paper's model: max magnitude difference | max phase difference |\n"
                      "|---|---:|---:|---:|---:|---:|---:|\n",
                      kFitLoHz, kFitHiHz);
    for (std::size_t j = 0; j < res.models.size(); ++j) {
      const auto& m = res.models[j];
      std::string vs = "- | -";
      if (j < res.measured.size()) {
        const BodeCurve& meas = res.measured[j];
        const BodeCurve paper =
            BodeFromModel("paper", ident::PoleModel::FromServoModel3(m.paper), meas.f_hz, kDt);
        double dm = 0.0, dp = 0.0;
        Over(meas, kFitLoHz, kFitHiHz, [&](std::size_t i) {
          dm = std::max(dm, std::abs(meas.magnitude[i] / paper.magnitude[i] - 1.0));
          dp = std::max(dp, std::abs(meas.phase_deg[i] - paper.phase_deg[i]));
        });
        vs = fmt::format("{:.1f} % | {:.1f} deg", 100 * dm, dp);
      }
      md << fmt::format("| {} | {:.2f} % | {:.2f} deg | {:.4f} | {:.2f} ms | {} |\n", m.condition, m.fit.max_mag_error_pct,
                        m.fit.max_phase_error_deg, m.fit.model.DcGain(), 1e3 * m.fit.model.DcLagS(), vs);
    }
  }
  return res;
}

// --- Figs. 7 and 8 -------------------------------------------------------------------------

std::vector<Table2Controller> ControllersOf(const std::string& condition) {
  std::vector<Table2Controller> out;
  for (const auto& row : Table2Controllers()) {
    if (row.condition == condition) out.push_back(row);
  }
  if (out.empty()) throw Error("ControllersOf", fmt::format("condition '{}' (allowed: 0.0A, 2.5A)", condition));
  return out;
}

namespace {

const BodeCurve* Named(const std::vector<BodeCurve>& curves, const std::string& prefix, const std::string& not_containing = "") {
  for (const auto& c : curves) {
    if (c.name.rfind(prefix, 0) == 0 && (not_containing.empty() || c.name.find(not_containing) == std::string::npos)) return &c;
  }
  return nullptr;
}

std::vector<Claim> CheckE2(const std::vector<BodeCurve>& curves, const std::string& condition) {
  std::vector<Claim> checks;
  const std::string ff_name = condition == "0.0A" ? "G_FF,0.0A" : "G_FF,2.5A";
  const BodeCurve* ff = nullptr;
  for (const auto& c : curves) {
    if (c.name == ff_name) ff = &c;
  }
  const BodeCurve* lp = Named(curves, ff_name + " + LP");
  const BodeCurve* poly = Named(curves, "3rd Poly");
  const BodeCurve* lead = Named(curves, "Lead Comp");
  if (ff) {
    double mag = 0.0, lag = 0.0;
    Over(*ff, 0.5, 30.0, [&](std::size_t i) {
      mag = std::max(mag, std::abs(ff->magnitude[i] - 1.0));
      lag = std::max(lag, std::abs(ff->lag_ms[i]));
    });
    checks.push_back({fmt::format("the proposed FF ({}) within +/-10 % magnitude and +/-1 ms time lag up to 30 Hz", ff_name),
                      mag <= 0.10 && lag <= 1.0,
                      fmt::format("0.5-30 Hz: largest |magnitude - 1| {:.1f} %, largest |lag| {:.2f} ms", 100 * mag, lag)});
  }
  if (lp) {
    double lo = 1e9, hi = -1e9, sum = 0.0;
    int n = 0;
    Over(*lp, 2.0, 30.0, [&](std::size_t i) {
      lo = std::min(lo, lp->lag_ms[i]);
      hi = std::max(hi, lp->lag_ms[i]);
      sum += lp->lag_ms[i];
      ++n;
    });
    const double mean = n ? sum / n : std::nan("");
    checks.push_back({"FF + LP: a nearly constant time lag of about 1.25 ms (low-pass group delay plus half a sample)",
                      mean >= 1.0 && mean <= 1.5 && hi - lo <= 0.5,
                      fmt::format("2-30 Hz: mean lag {:.2f} ms, from {:.2f} to {:.2f} ms", mean, lo, hi)});
  }
  if (poly) {
    double min_mag = 1e9, min_at = 0.0, max_hi = 0.0;
    Over(*poly, 5.0, 25.0, [&](std::size_t i) {
      if (poly->magnitude[i] < min_mag) {
        min_mag = poly->magnitude[i];
        min_at = poly->f_hz[i];
      }
    });
    Over(*poly, 35.0, 50.0, [&](std::size_t i) { max_hi = std::max(max_hi, poly->magnitude[i]); });
    checks.push_back({"3rd Poly: magnitude undershoot between about 5 and 25 Hz and growth above about 35 Hz",
                      min_mag < 0.98 && max_hi > 1.05,
                      fmt::format("smallest magnitude {:.3f} at {:.1f} Hz; largest above 35 Hz {:.3f}", min_mag, min_at, max_hi)});
  }
  if (lead) {
    const double m10 = At(*lead, lead->magnitude, 10.0), m20 = At(*lead, lead->magnitude, 20.0),
                 m30 = At(*lead, lead->magnitude, 30.0), l20 = At(*lead, lead->lag_ms, 20.0),
                 l30 = At(*lead, lead->lag_ms, 30.0);
    checks.push_back({"Lead Comp: growing magnitude and under-compensated time lag above about 10 Hz",
                      m30 > m20 && m20 > m10 && m20 > 1.02 && l20 > 0.2 && l30 > l20,
                      fmt::format("magnitude {:.3f} / {:.3f} / {:.3f} at 10 / 20 / 30 Hz; lag {:.2f} / {:.2f} ms at 20 / 30 Hz",
                                  m10, m20, m30, l20, l30)});
  }
  return checks;
}

}  // namespace

Fig78Result ReproduceFig78(const ReproduceOptions& opts, const std::string& figure) {
  if (figure != "fig7" && figure != "fig8") throw Error("ReproduceFig78", "figure must be fig7 or fig8");
  PrepareOutDir(opts.out_dir);
  RequirePlant(opts.plant, opts.out_dir);
  Fig78Result res;
  res.condition = figure == "fig7" ? "0.0A" : "2.5A";
  const double duration = opts.quick ? kQuickS : kFullS;
  const auto controllers = ControllersOf(res.condition);
  std::vector<RunSpec> specs;
  for (const auto& c : controllers) {
    auto s = FrequencyScenario(res.condition, c.controller, opts.plant, duration);
    s.run.name = Slug(fmt::format("{} {}", figure, c.name));
    specs.push_back({fmt::format("{} {}", figure, c.name), s, opts.out_dir / "runs" / Slug(c.name)});
  }
  const auto results = RunAll(specs, opts, figure);
  std::size_t segments = 0, segment_length = 0;
  for (std::size_t j = 0; j < controllers.size(); ++j) {
    const Trace t = ReadTrace(results[j].dir);
    segment_length = ident::DefaultSegmentLength(t.r_mm.size(), kDt, 0.0);
    const auto est = signal::H1Estimate(t.r_mm, t.y_mm, kDt, segment_length);
    segments = est.segments;
    res.curves.push_back(BodeFromEstimate(controllers[j].name, est, kPlotMaxHz));
  }
  res.checks = CheckE2(res.curves, res.condition);

  WriteCurvesCsv(opts.out_dir / (figure + ".csv"), "controller", res.curves);
  const std::string cond_text = res.condition == "0.0A" ? "0.0 A" : "2.5 A";
  Figure fig = BodeFigure(figure,
                          fmt::format("Fig. {}: G_yr with {} in the damper ({} plant)", figure == "fig7" ? 7 : 8,
                                      cond_text, opts.plant),
                          res.curves, {}, res.condition == "0.0A" ? "G_FF,0.0A" : "G_FF,2.5A");
  fig.panels[0].y_range = std::make_pair(0.0, 2.5);     // the polynomial and the lead grow fast near 50 Hz
  fig.panels[2].y_range = std::make_pair(-5.0, 12.0);   // ms
  fig.gnuplot = opts.gnuplot;
  Plot(fig, opts.out_dir);
  {
    std::ofstream md(opts.out_dir / (figure + ".md"));
    md << fmt::format("# Fig. {}: G_yr for each controller with {} in the damper\n\n", figure == "fig7" ? 7 : 8, cond_text)
       << fmt::format("Made by `rths reproduce {}{} --plant {}` on {}.\n\n", figure, opts.quick ? " --quick" : "",
                      opts.plant, UtcStamp())
       << fmt::format("Desired displacement r: BLWN 0-50 Hz, RMS {} mm, {:g} s, through each controller of Table 1 "
                      "for the condition; G_yr by H1 (Welch, Hann, 50 % overlap, {} segments of {:.3g} s). "
                      "Curves in `{}.csv`, figure `{}.png`.\n\n",
                      kRmsMm, duration, segments, segment_length * kDt, figure, figure)
       << "| controller | magnitude at 10 / 20 / 30 / 40 Hz | time lag at 10 / 20 / 30 / 40 Hz [ms] |\n|---|---|---|\n";
    for (const auto& c : res.curves) {
      md << fmt::format("| {} | {:.3f} / {:.3f} / {:.3f} / {:.3f} | {:.2f} / {:.2f} / {:.2f} / {:.2f} |\n", c.name,
                        At(c, c.magnitude, 10), At(c, c.magnitude, 20), At(c, c.magnitude, 30), At(c, c.magnitude, 40),
                        At(c, c.lag_ms, 10), At(c, c.lag_ms, 20), At(c, c.lag_ms, 30), At(c, c.lag_ms, 40));
    }
    md << "\n## E2's statements, measured on these curves\n\n"
       << (opts.plant == "linear"
               ? "The plant is the design model of the condition's controllers (Eq. 28 / 29), as E2 asks.\n\n"
               : "E2 states these for a plant equal to the design model (`--plant linear`); on the physical plant "
                 "they are reported, not required.\n\n");
    for (const auto& c : res.checks) {
      md << fmt::format("- **{}** {}.  \n  {}\n", c.holds ? "Holds:" : "Does not hold:", c.text, c.detail);
    }
  }
  return res;
}

}  // namespace rths::report
