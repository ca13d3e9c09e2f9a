// What the frequency-domain reproductions share (studies/frequency.h): Fig. 6 (E1, G_yu) and
// Figs. 7-8 (E2, G_yr through each controller of Table 1). Each measurement is a lockstep run with a
// predefined BLWN 0-50 Hz desired displacement.
#include "studies/frequency.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "io/bode_figure.h"
#include "io/csv.h"
#include "studies/figures.h"

namespace rths::studies {

namespace fs = std::filesystem;
using io::Series;
using io::Figure;
using io::CsvWriter;

signal::SignalSpec FrequencyExcitation() {
  signal::SignalSpec spec;
  spec.kind = signal::SignalKind::kBlwn;
  spec.band_hz = kFreqBandHz;
  spec.rms = kFreqRmsMm;
  spec.seed = 1;
  spec.discard_s = 2.0;
  spec.taper_s = kFreqTaperS;
  return spec;
}

scenario::Scenario FrequencyScenario(const std::string& condition, const control::ControllerConfig& controller,
                                     const std::string& plant, double duration_s) {
  if (condition != "0.0A" && condition != "2.5A") {
    throw Error("FrequencyScenario", fmt::format("condition '{}' (allowed: 0.0A, 2.5A)", condition));
  }
  scenario::Scenario s;
  s.run.name = "freq";
  s.run.dt_s = kFreqDtS;
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

std::vector<RunResult> RunFrequencyBatch(std::vector<RunSpec> specs, const ReproduceOptions& opts,
                                         const std::string& what) {
  const std::string intro =
      fmt::format("{}: {} lockstep runs on the {} plant, {} at a time", what, specs.size(), opts.plant, opts.jobs);
  const auto results = RunStudyBatch(&specs, opts, intro, [&](std::size_t done, std::size_t total, const RunResult& r) {
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

Figure BodeFigure(const std::string& name, const std::string& title, const std::vector<BodeCurve>& solid,
                  const std::vector<std::pair<BodeCurve, Series>>& styled, const std::string& proposed) {
  std::vector<io::BodeTrace> traces;
  auto add = [&traces](const BodeCurve& c, Series style) {
    io::BodeTrace t;
    t.curve = c;
    t.style = std::move(style);
    traces.push_back(std::move(t));
  };
  for (std::size_t i = 0; i < solid.size(); ++i) {
    const BodeCurve& c = solid[i];
    add(c, StyledSeries(c.name, ControllerStyle(c.name, !proposed.empty() && c.name == proposed, i)));
  }
  for (const auto& [c, style] : styled) add(c, style);
  io::BodeLayout layout;
  layout.f_range_hz = {0.0, kFreqPlotMaxHz};
  layout.left_margin_chars = 10;
  // Time lag: the range of the curves from 2 Hz up. Below, -phase / (2 pi f) divides the
  // estimate's phase noise by a small f and would squeeze the rest into a few pixels.
  double lo = 1e300, hi = -1e300;
  for (const auto& t : traces) {
    for (std::size_t i = 0; i < t.curve.f_hz.size(); ++i) {
      const double l = t.curve.lag_ms[i];
      if (t.curve.f_hz[i] >= 2.0 && std::isfinite(l)) lo = std::min(lo, l), hi = std::max(hi, l);
    }
  }
  if (lo <= hi) {
    const double pad = std::max(0.5, 0.1 * (hi - lo));
    layout.lag_range_ms = std::make_pair(std::floor(lo - pad), std::ceil(hi + pad));
  }
  Figure fig = io::BodeFigure(layout, traces);
  fig.name = name;
  fig.title = title;
  fig.width_px = 1200;
  fig.panel_height_px = 330;
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

double ValueAt(const BodeCurve& c, const std::vector<double>& col, double f) {
  for (std::size_t i = 1; i < c.f_hz.size(); ++i) {
    if (c.f_hz[i] >= f) {
      const double w = (f - c.f_hz[i - 1]) / (c.f_hz[i] - c.f_hz[i - 1]);
      return col[i - 1] + w * (col[i] - col[i - 1]);
    }
  }
  return std::nan("");
}

}  // namespace rths::studies
