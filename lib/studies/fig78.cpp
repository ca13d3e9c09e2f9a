// Figs. 7 and 8 (docs/experiments.md E2): the BLWN of E1 as the desired displacement through each
// controller of Table 1 for one condition, G_yr by H1, and E2's statements checked on the curves.
#include "studies/fig78.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "ident/identify.h"
#include "io/run_signals.h"

namespace rths::studies {

std::vector<Table2Controller> ControllersOf(const std::string& condition) {
  std::vector<Table2Controller> out;
  for (const auto& row : Table2Controllers()) {
    if (row.condition == condition) out.push_back(row);
  }
  if (out.empty()) throw Error("ControllersOf", fmt::format("condition '{}' (allowed: 0.0A, 2.5A)", condition));
  return out;
}

namespace {

const BodeCurve* CurveNamed(const std::vector<BodeCurve>& curves, const std::string& prefix, const std::string& not_containing = "") {
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
  const BodeCurve* lp = CurveNamed(curves, ff_name + " + LP");
  const BodeCurve* poly = CurveNamed(curves, "3rd Poly");
  const BodeCurve* lead = CurveNamed(curves, "Lead Comp");
  if (ff) {
    double mag = 0.0, lag = 0.0;
    ForEachIn(*ff, 0.5, 30.0, [&](std::size_t i) {
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
    ForEachIn(*lp, 2.0, 30.0, [&](std::size_t i) {
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
    ForEachIn(*poly, 5.0, 25.0, [&](std::size_t i) {
      if (poly->magnitude[i] < min_mag) {
        min_mag = poly->magnitude[i];
        min_at = poly->f_hz[i];
      }
    });
    ForEachIn(*poly, 35.0, 50.0, [&](std::size_t i) { max_hi = std::max(max_hi, poly->magnitude[i]); });
    checks.push_back({"3rd Poly: magnitude undershoot between about 5 and 25 Hz and growth above about 35 Hz",
                      min_mag < 0.98 && max_hi > 1.05,
                      fmt::format("smallest magnitude {:.3f} at {:.1f} Hz; largest above 35 Hz {:.3f}", min_mag, min_at, max_hi)});
  }
  if (lead) {
    const double m10 = ValueAt(*lead, lead->magnitude, 10.0), m20 = ValueAt(*lead, lead->magnitude, 20.0),
                 m30 = ValueAt(*lead, lead->magnitude, 30.0), l20 = ValueAt(*lead, lead->lag_ms, 20.0),
                 l30 = ValueAt(*lead, lead->lag_ms, 30.0);
    checks.push_back({"Lead Comp: growing magnitude and under-compensated time lag above about 10 Hz",
                      m30 > m20 && m20 > m10 && m20 > 1.02 && l20 > 0.2 && l30 > l20,
                      fmt::format("magnitude {:.3f} / {:.3f} / {:.3f} at 10 / 20 / 30 Hz; lag {:.2f} / {:.2f} ms at 20 / 30 Hz",
                                  m10, m20, m30, l20, l30)});
  }
  return checks;
}

}  // namespace

namespace {

std::vector<RunSpec> Fig78Specs(const ReproduceOptions& opts, const std::string& figure,
                                const std::vector<Table2Controller>& controllers, double duration,
                                const std::string& condition) {
  std::vector<RunSpec> specs;
  for (const auto& c : controllers) {
    auto s = FrequencyScenario(condition, c.controller, opts.plant, duration);
    s.run.name = Slug(fmt::format("{} {}", figure, c.name));
    specs.push_back({fmt::format("{} {}", figure, c.name), s, opts.out_dir / "runs" / Slug(c.name)});
  }
  return specs;
}

/// The Welch segmentation of the estimates (the same for every run of a study).
struct Segmentation {
  std::size_t segments = 0, segment_length = 0;
};

/// The table: G_yr of each controller's run.
std::vector<BodeCurve> Fig78Curves(const std::vector<RunResult>& results,
                                   const std::vector<Table2Controller>& controllers, Segmentation* seg) {
  std::vector<BodeCurve> curves;
  for (std::size_t j = 0; j < controllers.size(); ++j) {
    const io::RunSignals t = io::ReadRunSignals(results[j].dir);
    const auto& r = t.At("r_mm").values;
    seg->segment_length = ident::DefaultSegmentLength(r.size(), kFreqDtS, 0.0);
    const auto est = signal::H1Estimate(r, t.At("y_mm").values, kFreqDtS, seg->segment_length);
    seg->segments = est.segments;
    curves.push_back(BodeFromEstimate(controllers[j].name, est, kFreqPlotMaxHz));
  }
  return curves;
}

io::Figure Fig78Figure(const Fig78Result& res, const ReproduceOptions& opts, const std::string& figure) {
  const std::string cond_text = res.condition == "0.0A" ? "0.0 A" : "2.5 A";
  io::Figure fig = BodeFigure(figure,
                              fmt::format("Fig. {}: G_yr with {} in the damper ({} plant)", figure == "fig7" ? 7 : 8,
                                          cond_text, opts.plant),
                              res.curves, {}, res.condition == "0.0A" ? "G_FF,0.0A" : "G_FF,2.5A");
  fig.panels[0].y_range = std::make_pair(0.0, 2.5);     // the polynomial and the lead grow fast near 50 Hz
  fig.panels[2].y_range = std::make_pair(-5.0, 12.0);   // ms
  fig.gnuplot = opts.gnuplot;
  return fig;
}

void WriteMarkdown(const Fig78Result& res, const ReproduceOptions& opts, const std::string& figure, double duration,
                   const Segmentation& seg) {
  const std::string cond_text = res.condition == "0.0A" ? "0.0 A" : "2.5 A";
  std::ofstream md(opts.out_dir / (figure + ".md"));
  md << fmt::format("# Fig. {}: G_yr for each controller with {} in the damper\n\n", figure == "fig7" ? 7 : 8, cond_text)
     << fmt::format("Made by `rths reproduce {}{} --plant {}` on {}.\n\n", figure, opts.quick ? " --quick" : "",
                    opts.plant, UtcStamp())
     << fmt::format("Desired displacement r: BLWN 0-50 Hz, RMS {} mm, {:g} s, through each controller of Table 1 "
                    "for the condition; G_yr by H1 (Welch, Hann, 50 % overlap, {} segments of {:.3g} s). "
                    "Curves in `{}.csv`, figure `{}.png`.\n\n",
                    kFreqRmsMm, duration, seg.segments, seg.segment_length * kFreqDtS, figure, figure)
     << "| controller | magnitude at 10 / 20 / 30 / 40 Hz | time lag at 10 / 20 / 30 / 40 Hz [ms] |\n|---|---|---|\n";
  for (const auto& c : res.curves) {
    md << fmt::format("| {} | {:.3f} / {:.3f} / {:.3f} / {:.3f} | {:.2f} / {:.2f} / {:.2f} / {:.2f} |\n", c.name,
                      ValueAt(c, c.magnitude, 10), ValueAt(c, c.magnitude, 20), ValueAt(c, c.magnitude, 30),
                      ValueAt(c, c.magnitude, 40), ValueAt(c, c.lag_ms, 10), ValueAt(c, c.lag_ms, 20),
                      ValueAt(c, c.lag_ms, 30), ValueAt(c, c.lag_ms, 40));
  }
  md << "\n## E2's statements, measured on these curves\n\n"
     << (opts.plant == "linear"
             ? "The plant is the design model of the condition's controllers (Eq. 28 / 29), as E2 asks.\n\n"
             : "E2 states these for a plant equal to the design model (`--plant linear`); on the physical plant "
               "they are reported, not required.\n\n");
  for (const auto& c : res.claims) {
    md << ClaimMarkdown(c);
  }
}

}  // namespace

Fig78Result ReproduceFig78(const ReproduceOptions& opts, const std::string& figure) {
  if (figure != "fig7" && figure != "fig8") throw Error("ReproduceFig78", "figure must be fig7 or fig8");
  PrepareOutDir(opts.out_dir, opts.batch.resume);
  RequirePlant(opts.plant, opts.out_dir);
  Fig78Result res;
  res.condition = figure == "fig7" ? "0.0A" : "2.5A";
  const double duration = opts.quick ? kFreqQuickS : kFreqFullS;
  const auto controllers = ControllersOf(res.condition);
  const auto results =
      RunFrequencyBatch(Fig78Specs(opts, figure, controllers, duration, res.condition), opts, figure);
  Segmentation seg;
  res.curves = Fig78Curves(results, controllers, &seg);
  res.claims = CheckE2(res.curves, res.condition);
  WriteCurvesCsv(opts.out_dir / (figure + ".csv"), "controller", res.curves);
  io::Plot(Fig78Figure(res, opts, figure), opts.out_dir);
  WriteMarkdown(res, opts, figure, duration, seg);
  return res;
}

}  // namespace rths::studies
