// The page of `rths diagnose` (report/diagnosis_page.h).
#include "report/diagnosis_page.h"

#include <cmath>

#include <fmt/format.h>

#include "diagnosis/report_figures.h"
#include "io/plot.h"
#include "report/html.h"

namespace rths::report {

namespace fs = std::filesystem;
using diagnosis::Result;
using diagnosis::Traces;

namespace {

/// The plots of the first test record as PNGs in dir; returns their names, *note says why some or all are missing.
std::vector<std::string> WritePlots(const Result& r, const Traces& traces, const fs::path& dir, std::string* note) {
  std::vector<std::string> pngs;
  if (traces.test.empty()) {
    *note = "<p>No traces: no plots.</p>\n";
    return pngs;
  }
  if (!io::GnuplotAvailable()) {
    *note = "<p>gnuplot is not installed (apt-get install gnuplot-nox): no plots.</p>\n";
    return pngs;
  }
  const auto& t = traces.test[0];
  const auto first = static_cast<std::size_t>(std::lround(r.options.warmup_s / t.dt_s));
  std::vector<io::Figure> figs = {diagnosis::SpectrumFigure(t, "y", first), diagnosis::FrfFigure(t, first)};
  if (!t.f_nom.empty()) figs.push_back(diagnosis::SpectrumFigure(t, "f", first));
  figs.push_back(diagnosis::ConditionFigure(r));
  figs.push_back(diagnosis::TraceFigure(t, "y"));
  if (!t.f_nom.empty()) figs.push_back(diagnosis::TraceFigure(t, "f"));
  for (const auto& f : figs) {
    if (f.panels.empty()) continue;
    try {
      io::Plot(f, dir);
      pngs.push_back(f.name + ".png");
    } catch (const std::exception& e) {
      *note += fmt::format("<p>plot {} failed: {}</p>\n", f.name, HtmlEscape(e.what()));
    }
  }
  return pngs;
}

/// The head of the page: the verdict, the model, the records.
std::string HeadHtml(const Result& r) {
  std::string h;
  h += HtmlHead("rths diagnose");
  h += "<h1>Sim-to-real gap diagnosis</h1>\n";
  h += fmt::format("<p><b>Verdict: {}</b></p>\n", HtmlEscape(diagnosis::VerdictText(r)));
  h += fmt::format("<p>Model: {}<br>Training records: {}<br>Test records: {}<br>dt = {} s, {} samples, runtime {:.2f} s</p>\n",
                   HtmlEscape(r.model_source), HtmlEscape(fmt::format("{}", fmt::join(r.train, ", "))),
                   HtmlEscape(fmt::format("{}", fmt::join(r.test, ", "))), r.dt_s, r.samples, r.runtime_s);
  return h;
}

/// The gap per channel and the effects.
std::string ChannelsAndEffectsHtml(const Result& r) {
  std::string h;
  h += "<h2>Gap per channel (test records)</h2>\n<table><tr><th>channel</th><th>NRMSE nominal [%]</th><th>train [%]</th>"
       "<th>after [%]</th><th>noise floor rms</th><th>residual / floor</th><th>whiteness Q20</th><th>status</th></tr>\n";
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      h += fmt::format("<tr><td>{}</td><td colspan=7>not diagnosed</td></tr>\n", c.channel);
      continue;
    }
    h += fmt::format("<tr><td>{}</td><td>{:.3f}</td><td>{:.3f}</td><td>{:.3f}</td><td>{:.4g} {}</td><td>{:.2f}</td>"
                     "<td>{:.0f}</td><td>{}</td></tr>\n",
                     c.channel, c.gap_test_pct, c.gap_train_pct, c.after_test_pct, c.noise_rms, c.channel == "y" ? "mm" : "kN",
                     c.floor_ratio, c.whiteness, c.status);
  }
  h += "</table>\n<h2>Effects (fitted on the training records, scored on the test records)</h2>\n"
       "<table><tr><th>effect</th><th>channel</th><th>parameters</th><th>test NRMSE after [%]</th><th>shrink [%]</th>"
       "<th>train NRMSE after [%]</th><th>selected</th></tr>\n";
  for (const auto& e : r.effects) {
    std::string ps;
    for (const auto& [k, v] : e.params) ps += fmt::format("{} = {:.4g}<br>", k, v);
    h += fmt::format("<tr{}><td>{}</td><td>{}</td><td>{}</td><td>{:.3f}</td><td>{:.1f}</td><td>{:.3f}</td>"
                     "<td>{}</td></tr>\n",
                     e.selected ? " class=sel" : "", e.name, e.channel, ps, e.test_nrmse_after, e.shrink_pct, e.train_nrmse_after,
                     e.selected ? fmt::format("yes ({})", e.order + 1) : "no");
  }
  return h + "</table>\n";
}

/// Where: the frequency bands, the state conditions and the time windows.
std::string WhereHtml(const Result& r) {
  std::string h;
  h += "<h2>Where: frequency bands (nominal residual, test records)</h2>\n<table><tr><th>channel</th><th>band [Hz]</th>"
       "<th>residual share [%]</th><th>signal share [%]</th><th>residual / signal in band [%]</th><th>coherence</th>"
       "<th>|H_meas / H_model|</th><th>phase diff [deg]</th></tr>\n";
  for (const auto& b : r.bands) {
    if (b.share_pct < 0.05 && b.signal_share_pct < 0.05) continue;
    h += fmt::format("<tr><td>{}</td><td>{:g}-{:g}</td><td>{:.1f}</td><td>{:.1f}</td><td>{:.2f}</td><td>{}</td><td>{}</td>"
                     "<td>{}</td></tr>\n",
                     b.channel, b.lo_hz, b.hi_hz, b.share_pct, b.signal_share_pct, b.rel_residual_pct,
                     b.coherence >= 0 ? fmt::format("{:.3f}", b.coherence) : "",
                     b.coherence >= 0 ? fmt::format("{:.3f}", b.gain_ratio) : "",
                     b.coherence >= 0 ? fmt::format("{:.2f}", b.phase_diff_deg) : "");
  }
  h += "</table>\n<h2>Where: state conditions</h2>\n<table><tr><th>channel</th><th>condition</th><th>residual share [%]</th>"
       "<th>sample share [%]</th><th>ratio</th><th>informative</th></tr>\n";
  for (const auto& c : r.conditions)
    h += fmt::format("<tr><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.1f}</td><td>{:.2f}</td><td>{}</td></tr>\n",
                     c.channel, c.name, c.share_pct, c.samples_pct, c.samples_pct > 0 ? c.share_pct / c.samples_pct : 0.0,
                     c.informative         ? std::string("yes")
                     : c.samples_pct <= 0.0 ? std::string("no: holds in no sample")
                                            : fmt::format("no: holds in {:.0f} % of the samples (more than {:.0f} %)",
                                                          c.samples_pct, r.options.max_condition_samples_pct));
  h += "</table>\n<h2>Where: time windows (largest shares)</h2>\n<table><tr><th>channel</th><th>record</th><th>t0 [s]</th>"
       "<th>t1 [s]</th><th>share [%]</th></tr>\n";
  for (const auto& t : r.time)
    h += fmt::format("<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.2f}</td><td>{:.1f}</td></tr>\n", t.channel,
                     HtmlEscape(t.record), t.t0_s, t.t1_s, t.share_pct);
  return h + "</table>\n";
}

}  // namespace

void WriteDiagnosisReport(const Result& r, const Traces& traces, const fs::path& dir) {
  std::string plot_note;
  const std::vector<std::string> pngs = WritePlots(r, traces, dir, &plot_note);
  std::string h = HeadHtml(r) + ChannelsAndEffectsHtml(r) + WhereHtml(r);
  if (!r.warnings.empty()) {
    h += "<h2>Warnings</h2>\n<ul>\n";
    for (const auto& w : r.warnings) h += "<li>" + HtmlEscape(w) + "</li>\n";
    h += "</ul>\n";
  }
  h += "<h2>Plots</h2>\n" + plot_note;
  for (const auto& p : pngs) h += fmt::format("<p><img src=\"{}\" alt=\"{}\" style=\"max-width:100%\"></p>\n", p, p);
  h += "<p>Method: docs/diagnosis.md. JSON: diagnosis.json.</p>\n</body></html>\n";
  WriteFileAtomically(dir / "report.html", h);
}

}  // namespace rths::report
