// Runs side by side (report/compare_page.h, docs/compare.md).
#include "report/compare_page.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/error.h"
#include "core/names.h"
#include "io/plot.h"
#include "report/html.h"
#include "report/run_figures.h"
#include "report/run_tables.h"
#include "signal/spectrum_axes.h"
#include "signal/metrics.h"
#include "signal/spectral.h"

namespace rths::report {
namespace {

namespace fs = std::filesystem;
using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Panel;
using io::Series;
using run_figures::Curve;
using run_figures::SegmentLength;
using run_figures::Strided;

struct CompareFigure {
  Figure figure;
  std::string heading, caption_html;
};

/// The runs as the page shows them: label, colour, signals over the common steps.
struct Overlay {
  const std::vector<RunData>* runs;
  std::vector<std::string> labels, colors;
  std::size_t n = 0;  ///< common steps
  double dt_s = 0;
  const std::vector<double>& Col(std::size_t run, const char* name) const {
    return (*runs)[run].signals.At(name).values;
  }
};

/// `x` over its first n samples.
std::vector<double> Head(const std::vector<double>& x, std::size_t n) {
  return {x.begin(), x.begin() + static_cast<std::ptrdiff_t>(std::min(n, x.size()))};
}

/// The legends go above the axes, in a row, in a smaller font with short samples: with several
/// runs overlaid no corner of the data is free, and beside the axes they would take a third of the
/// width. A panel whose entries (title and colour) an earlier panel's legend already shows has none:
/// a run has one colour in every panel. Stacked axes line up.
void KeysAbove(Figure* f) {
  std::set<std::pair<std::string, std::string>> shown;
  for (auto& p : f->panels) {
    bool news = false;
    for (const auto& s : p.series) news = news || (!s.title.empty() && !shown.count({s.title, s.color}));
    p.key = news ? "outside top center horizontal font ',9' samplen 3" : "off";
    for (const auto& s : p.series) shown.insert({s.title, s.color});
    if (f->columns == 1) p.left_margin_chars = 11;
  }
}

/// The runs in drawing order: the largest peak |column| first, the smallest last, so that a run
/// that strays far is drawn beneath and the runs close together stay visible over it.
std::vector<std::size_t> LargestFirst(const Overlay& ov, const char* column) {
  std::vector<std::size_t> order(ov.labels.size());
  std::vector<double> peak(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    peak[i] = signal::PeakAbs(Head(ov.Col(i, column), ov.n));
    if (!std::isfinite(peak[i])) peak[i] = std::numeric_limits<double>::infinity();
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return peak[a] > peak[b]; });
  return order;
}

Figure NewFigure(const std::string& name, const CompareOptions& o) { return run_figures::PageFrame(name, o.gnuplot); }

/// A time history of run `run`'s column over the common steps, min/max decimated.
Series History(const Overlay& ov, std::size_t run, const char* column, const std::string& title,
               const CompareOptions& o) {
  const std::vector<double> t = Head(ov.Col(run, "t_s"), ov.n);
  return run_figures::History(title, ov.colors[run], t, Head(ov.Col(run, column), ov.n), o.max_plot_points);
}

/// r of the first run, dashed black: the reference every y is drawn against.
Series Reference(Series s) {
  s.color = "black";
  s.dash = 2;
  s.width = 1.6;
  return s;
}

/// Run `run`'s column minus the first run's, step by step, over the common steps.
Series Difference(const Overlay& ov, std::size_t run, const char* column, const CompareOptions& o) {
  std::vector<double> d = Head(ov.Col(run, column), ov.n);
  const std::vector<double>& first = ov.Col(0, column);
  for (std::size_t k = 0; k < d.size(); ++k) d[k] -= first[k];
  return run_figures::History(ov.labels[run], ov.colors[run], Head(ov.Col(run, "t_s"), ov.n), d, o.max_plot_points);
}

CompareFigure Histories(const Overlay& ov, const CompareOptions& o) {
  // Runs that track well lie on one another at the scale of the motion: each quantity is drawn
  // again as every other run's difference from the first, on its own axis.
  Panel disp = MakePanel("Displacement", "t [s]", "displacement [mm]");
  disp.series.push_back(Reference(History(ov, 0, "r_mm", "r (" + ov.labels[0] + ")", o)));
  Panel disp_d =
      MakePanel("Displacement minus the first run's: y - y (" + ov.labels[0] + ")", "t [s]", "difference [mm]");
  Panel force = MakePanel("Specimen force", "t [s]", "force [kN]");
  Panel force_d = MakePanel("Force minus the first run's: f - f (" + ov.labels[0] + ")", "t [s]", "difference [kN]");
  for (const std::size_t i : LargestFirst(ov, "e_mm")) {
    disp.series.push_back(History(ov, i, "y_mm", ov.labels[i], o));
    force.series.push_back(History(ov, i, "f_kN", ov.labels[i], o));
    if (i == 0) continue;
    disp_d.series.push_back(Difference(ov, i, "y_mm", o));
    force_d.series.push_back(Difference(ov, i, "f_kN", o));
  }
  CompareFigure cf{NewFigure("compare_histories", o), "Time histories", ""};
  cf.figure.panels = {disp, disp_d, force, force_d};
  cf.figure.panel_height_px = 260;
  cf.caption_html = "Measured displacement y of every run with the desired displacement r of the first (dashed) "
                    "[mm], and each other run's y minus the first run's [mm]; measured force f [kN], and each other "
                    "run's f minus the first run's [kN]. Aligned by step (t = k dt); the run with the largest "
                    "tracking error drawn first, beneath; each curve keeps the minimum and maximum of its samples "
                    "per bucket (every peak).";
  return cf;
}

CompareFigure ErrorFigure(const Overlay& ov, const CompareOptions& o) {
  Panel err = MakePanel("Tracking error e = r - y", "t [s]", "e [mm]");
  std::size_t at = 0, worst_run = 0;
  double worst = -1;
  for (const std::size_t i : LargestFirst(ov, "e_mm")) err.series.push_back(History(ov, i, "e_mm", ov.labels[i], o));
  for (std::size_t i = 0; i < ov.labels.size(); ++i) {
    std::size_t k = 0;
    const double p = signal::PeakAbs(Head(ov.Col(i, "e_mm"), ov.n), &k);
    if (p > worst) worst = p, at = k, worst_run = i;
  }
  const std::size_t half = static_cast<std::size_t>(std::lround(0.25 / ov.dt_s));
  const std::size_t lo = at > half ? at - half : 0, hi = std::min(ov.n, at + half + 1);
  const auto idx = Strided(lo, hi, o.max_plot_points);
  const auto& t = ov.Col(0, "t_s");
  Panel zoom = MakePanel(fmt::format("Around the largest |e| ({:.4g} mm, {}, t = {:.4f} s)", worst,
                                     ov.labels[worst_run], t[at]),
                         "t [s]", "displacement [mm]");
  zoom.x_range = {{t[lo], t[hi - 1]}};
  zoom.series.push_back(Reference(Curve("r (" + ov.labels[0] + ")", "black", t, ov.Col(0, "r_mm"), idx)));
  for (const std::size_t i : LargestFirst(ov, "e_mm")) {
    zoom.series.push_back(Curve(ov.labels[i], ov.colors[i], t, ov.Col(i, "y_mm"), idx));
  }
  CompareFigure cf{NewFigure("compare_error", o), "Tracking error", ""};
  cf.figure.panels = {err, zoom};
  cf.figure.panel_height_px = 340;
  cf.caption_html = "Top: e = r - y of every run [mm], each against its own r. Bottom: r of the first run (dashed) "
                    "and every y [mm] over the 0.5 s around the largest |e| of any run, every step. The run with the "
                    "largest |e| is drawn first, beneath the others.";
  return cf;
}

CompareFigure Loops(const Overlay& ov, const CompareOptions& o) {
  Panel fd = MakePanel("Force-displacement", "y [mm]", "f [kN]");
  // The paper's axes (Fig. 11): the specimen's force against its displacement and velocity, the
  // measured y and its low-passed derivative (run_figures::LoopVelocity says why not y's central
  // difference or r'). A nearly elastic specimen (the benchmark's spring) draws a line against y:
  // its loop is the one against y'.
  Panel fv = MakePanel("Force-velocity", run_figures::LoopVelocityLabel(ov.dt_s), "f [kN]");
  const auto idx = Strided(0, ov.n, o.max_loop_points);
  for (const std::size_t i : LargestFirst(ov, "e_mm")) {
    const std::vector<double> y = Head(ov.Col(i, "y_mm"), ov.n);
    const std::vector<double> f = Head(ov.Col(i, "f_kN"), ov.n);
    fd.series.push_back(Curve(ov.labels[i], ov.colors[i], y, f, idx));
    fv.series.push_back(Curve(ov.labels[i], ov.colors[i], run_figures::LoopVelocity(y, ov.dt_s), f, idx));
  }
  CompareFigure cf{NewFigure("compare_loops", o), "Force loops", ""};
  cf.figure.panels = {fd, fv};
  cf.figure.columns = 2;
  cf.figure.panel_height_px = 450;
  cf.caption_html = fmt::format("Measured force f [kN] against y [mm] and against y' [mm/s] (y low-passed at {:g} Hz, "
                                "zero phase, and differentiated: sensor noise on y does not hide the loop), every run "
                                "over the common steps, the run with the largest tracking error drawn first. A nearly "
                                "elastic specimen draws a line against y; its loop is the one against y'.",
                                run_figures::LoopVelocityCutoffHz(ov.dt_s));
  return cf;
}

std::optional<CompareFigure> Spectra(const Overlay& ov, const CompareOptions& o) {
  if (ov.n < 128) return std::nullopt;
  const std::size_t l = SegmentLength(ov.n, ov.dt_s, o.welch_segment_s);
  std::vector<double> f(l / 2 + 1);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = static_cast<double>(i) / (static_cast<double>(l) * ov.dt_s);
  const std::vector<double> r_psd = signal::WelchPsd(Head(ov.Col(0, "r_mm"), ov.n), ov.dt_s, l);
  std::vector<std::vector<double>> y_psd, e_psd;
  for (std::size_t i = 0; i < ov.labels.size(); ++i) {
    y_psd.push_back(signal::WelchPsd(Head(ov.Col(i, "y_mm"), ov.n), ov.dt_s, l));
    e_psd.push_back(signal::WelchPsd(Head(ov.Col(i, "e_mm"), ov.n), ov.dt_s, l));
  }
  auto panel = [&](const std::string& title, const std::string& ylabel, const std::vector<std::vector<double>>& psds,
                   bool with_r) {
    Panel p = MakePanel(title, "f [Hz]", ylabel);
    p.log_y = true;
    std::vector<const std::vector<double>*> curves;
    for (const auto& c : psds) curves.push_back(&c);
    if (with_r) curves.push_back(&r_psd);
    const signal::SpectrumAxes ax = signal::SpectrumAxesOf(f, r_psd, curves, 40.0, 1.5, 8.0);
    std::vector<std::size_t> idx;
    for (std::size_t i = 1; i < f.size() && f[i] <= ax.f_hi_hz; ++i) idx.push_back(i);
    if (with_r) p.series.push_back(Reference(Curve("r (" + ov.labels[0] + ")", "black", f, r_psd, idx)));
    for (std::size_t i = 0; i < psds.size(); ++i) p.series.push_back(Curve(ov.labels[i], ov.colors[i], f, psds[i], idx));
    p.x_range = {{0.0, ax.f_hi_hz}};
    if (ax.psd_hi > 0) p.y_range = {{ax.psd_lo, ax.psd_hi}};
    return p;
  };
  CompareFigure cf{NewFigure("compare_spectra", o), "Spectra", ""};
  cf.figure.panels = {panel("Measured displacement y", "PSD [mm^2/Hz]", y_psd, true),
                      panel("Tracking error e = r - y", "PSD [mm^2/Hz]", e_psd, false)};
  cf.figure.columns = 2;
  cf.figure.panel_height_px = 380;
  cf.caption_html = fmt::format(
      "Welch power spectral densities (Hann, {} steps = {:.3g} s per segment, 50 % overlap) of y (with r of the "
      "first run, dashed) and of e [mm<sup>2</sup>/Hz], over the band that carries r (up to 1.5 times the highest "
      "frequency where its PSD is within 40 dB of its peak), down to eight decades below the highest value.",
      l, static_cast<double>(l) * ov.dt_s);
  return cf;
}

/// Unique labels: the given ones, or the runs' folder names (a duplicate gets " (2)", ...).
std::vector<std::string> Labels(const std::vector<RunData>& runs, const CompareOptions& o) {
  std::vector<std::string> labels = o.labels;
  if (labels.empty()) {
    for (const auto& r : runs) labels.push_back(fs::absolute(r.run_dir).lexically_normal().filename().string());
  }
  std::map<std::string, int> seen;
  for (auto& l : labels) {
    if (const int n = ++seen[l]; n > 1) l += fmt::format(" ({})", n);
  }
  return labels;
}

std::string SummaryTable(const std::vector<RunData>& runs, const std::vector<std::string>& labels) {
  using run_tables::JsonNumber;
  using run_tables::JsonText;
  auto row = [&](const std::string& name, auto cell) {
    std::string h = "<tr><th>" + name + "</th>";
    for (const auto& r : runs) h += "<td>" + cell(r) + "</td>";
    return h + "</tr>\n";
  };
  std::string h = "<table class=\"compare\">\n<tr><th></th>";
  for (const auto& l : labels) h += "<th>" + HtmlEscape(l) + "</th>";
  h += "</tr>\n";
  h += row("folder", [](const RunData& r) { return HtmlEscape(r.run_dir.string()); });
  h += row("status", [](const RunData& r) {
    if (!r.summary.is_object()) return std::string(r.log_complete ? "log complete (no summary.json)" : "log truncated");
    std::string s = HtmlEscape(JsonText(r.summary, "status", "?")) + fmt::format(" (exit {})", r.summary.value("exit_code", -1));
    const std::string stopped = JsonText(r.summary, "stopped", "no");
    return stopped == "no" ? s : s + ": " + HtmlEscape(stopped);
  });
  h += row("controller", [](const RunData& r) { return r.scenario ? std::string(NameOf(control::kControllerKindNames, r.scenario->controller.kind)) : std::string("?"); });
  h += row("steps", [](const RunData& r) {
    return fmt::format("{} of {} ({:.4g} s)", r.signals.steps(), r.steps_planned,
                       static_cast<double>(r.signals.steps()) * r.signals.dt_s);
  });
  h += row("tracking error (RMS, Eq. 31)", [](const RunData& r) {
    return fmt::format("{:.4g} %", r.metrics.tracking_nrmse_pct);
  });
  h += row("e = r - y: RMS, peak", [](const RunData& r) {
    if (r.signals.steps() == 0) return std::string("-");
    const auto& e = r.signals.At("e_mm").values;
    std::size_t at = 0;
    const double p = signal::PeakAbs(e, &at);
    return fmt::format("{:.4g} mm, {:.4g} mm at {:.4f} s", signal::Rms(e), p, r.signals.At("t_s").values[at]);
  });
  h += row("peak |y|", [](const RunData& r) { return fmt::format("{:.4g} mm", r.metrics.peak_displacement_mm); });
  h += row("peak |f|", [](const RunData& r) { return fmt::format("{:.4g} kN", r.metrics.peak_force_kN); });
  // The benchmark's J1-J9 (summary.json "benchmark_criteria"), where any run has them, rounded as
  // the benchmark reports them.
  if (std::any_of(runs.begin(), runs.end(), [](const RunData& r) { return BenchmarkCriteriaOf(r).has_value(); })) {
    for (int j = 1; j <= 9; ++j) {
      h += row(fmt::format("benchmark J{}", j), [&](const RunData& r) {
        const auto c = BenchmarkCriteriaOf(r);
        const double v = c ? c->Rounded().At(j - 1) : std::nan("");
        return !std::isfinite(v) ? std::string("-") : j == 1 ? fmt::format("{:.1f} ms", v) : fmt::format("{:.2f} %", v);
      });
    }
  }
  h += row("rate", [](const RunData& r) {
    const auto rate = JsonNumber(r.summary, "steps_per_s");
    return rate && *rate > 0 ? fmt::format("{:.0f} steps/s ({:.3g}x real time)", *rate, *rate * r.signals.dt_s)
                             : std::string("-");
  });
  return h + "</table>\n";
}

/// The scenario a run ran, as TOML in full (every default written), so two files that differ only
/// in what they leave to defaults compare equal; the folder's text if it does not load.
std::string FullScenario(const RunData& r) { return r.scenario ? scenario::ToToml(*r.scenario) : r.scenario_toml; }

std::string DifferencesTable(const std::vector<std::string>& texts, const std::vector<std::string>& labels,
                             const std::vector<std::string>& keys) {
  if (keys.empty()) return "<p id=\"no-differences\">The runs' scenarios are the same, key by key.</p>\n";
  std::vector<std::map<std::string, std::string>> values;
  for (const auto& text : texts) {
    std::map<std::string, std::string> m;
    for (auto& kv : scenario::FlattenScenario(text)) m[kv.key] = kv.value;
    values.push_back(std::move(m));
  }
  std::string h = "<table class=\"compare\" id=\"differences\">\n<tr><th>key</th>";
  for (const auto& l : labels) h += "<th>" + HtmlEscape(l) + "</th>";
  h += "</tr>\n";
  for (const auto& k : keys) {
    h += "<tr><th><code>" + HtmlEscape(k) + "</code></th>";
    for (const auto& m : values) {
      const auto it = m.find(k);
      h += "<td>" + (it == m.end() ? std::string("<em>absent</em>") : "<code>" + HtmlEscape(it->second) + "</code>") + "</td>";
    }
    h += "</tr>\n";
  }
  return h + "</table>\n";
}

}  // namespace

std::vector<std::string> DifferingKeys(const std::vector<std::string>& toml_texts) {
  std::vector<std::map<std::string, std::string>> maps;
  std::vector<std::string> order;
  std::set<std::string> seen;
  for (const auto& text : toml_texts) {
    std::map<std::string, std::string> m;
    for (auto& kv : scenario::FlattenScenario(text)) {
      if (seen.insert(kv.key).second) order.push_back(kv.key);
      m[kv.key] = kv.value;
    }
    maps.push_back(std::move(m));
  }
  std::vector<std::string> differ;
  for (const auto& key : order) {
    const auto first = maps[0].find(key);
    for (std::size_t i = 1; i < maps.size(); ++i) {
      const auto it = maps[i].find(key);
      const bool same = (first == maps[0].end()) == (it == maps[i].end()) &&
                        (first == maps[0].end() || first->second == it->second);
      if (!same) {
        differ.push_back(key);
        break;
      }
    }
  }
  return differ;
}

CompareFiles WriteComparison(const std::vector<RunData>& runs, const CompareOptions& o) {
  if (runs.size() < 2) throw Error("rths compare", "give at least two run folders");
  if (!o.labels.empty() && o.labels.size() != runs.size()) {
    throw Error("--labels", fmt::format("{} labels for {} runs: give one per run", o.labels.size(), runs.size()));
  }
  if (o.out_dir.empty()) throw Error("rths compare", "no output folder");
  Overlay ov{&runs, Labels(runs, o), {}, runs[0].signals.steps(), runs[0].signals.dt_s};
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (std::abs(runs[i].signals.dt_s - ov.dt_s) > 1e-12 * ov.dt_s) {
      throw Error(runs[i].run_dir.string(), fmt::format("its step is {} s, {}'s is {} s: runs are compared step by step, "
                                                        "so they must share dt",
                                                        runs[i].signals.dt_s, runs[0].run_dir.string(), ov.dt_s));
    }
    ov.n = std::min(ov.n, runs[i].signals.steps());
    const auto& palette = io::ReadableColors();
    ov.colors.push_back(palette[i % palette.size()]);
  }
  if (!io::GnuplotAvailable(o.gnuplot)) throw Error("gnuplot", "not found: install gnuplot (apt-get install gnuplot-nox)");
  CompareFiles files;
  files.aligned_steps = static_cast<std::int64_t>(ov.n);
  std::vector<std::string> texts;
  for (const auto& r : runs) texts.push_back(FullScenario(r));
  files.differing_keys = DifferingKeys(texts);

  std::vector<CompareFigure> figures;
  if (ov.n >= 2) {
    figures = {ErrorFigure(ov, o), Histories(ov, o), Loops(ov, o)};  // the tracking error first, as in the report
    if (auto s = Spectra(ov, o)) figures.push_back(*s);
  }
  const fs::path fig_dir = o.out_dir / "figures";
  fs::create_directories(fig_dir);
  std::vector<std::future<io::PlotFiles>> jobs;
  for (auto& cf : figures) KeysAbove(&cf.figure);
  for (const auto& cf : figures) {
    jobs.push_back(std::async(std::launch::async, [&cf, &fig_dir] { return io::Plot(cf.figure, fig_dir); }));
  }
  for (auto& j : jobs) files.figures.push_back(j.get().png);

  std::string h = HtmlHead("rths compare: " + fmt::format("{}", fmt::join(ov.labels, ", ")));
  h += "<h1>Runs compared</h1>\n";
  h += fmt::format("<p>{} runs, aligned by step (t = k dt, dt = {:g} s) over the {} steps they all have ({:.4g} s).</p>\n",
                   runs.size(), ov.dt_s, ov.n, static_cast<double>(ov.n) * ov.dt_s);
  h += "<h2 id=\"summary\">Summary</h2>\n" + SummaryTable(runs, ov.labels);
  h += "<h2 id=\"scenario\">Scenario differences</h2>\n" + DifferencesTable(texts, ov.labels, files.differing_keys);
  h += "<h2 id=\"figures\">Figures</h2>\n";
  if (figures.empty()) h += "<p>No figures: a run has fewer than 2 complete steps.</p>\n";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const std::string png = files.figures[i].filename().string();
    h += FigureHtml(figures[i].figure.name, figures[i].heading, png, figures[i].figure.width_px, figures[i].caption_html);
  }
  h += "</body></html>\n";
  files.html = o.out_dir / "compare.html";
  WriteFileAtomically(files.html, h);
  return files;
}

}  // namespace rths::report
