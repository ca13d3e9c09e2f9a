// A report for every run (docs/report.md): report.html and figures/*.png from a run folder.
// The figures are in run_figures.cpp, the tables in run_tables.cpp, the HTML writer in html.cpp.
#include "report/run_report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"
#include "io/plot.h"
#include "report/html.h"
#include "report/run_figures.h"
#include "report/run_tables.h"

namespace rths::report {

namespace fs = std::filesystem;
using run_figures::PageFigure;

namespace {

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string(), "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void CheckOptions(const RunReportOptions& o) {
  if (o.max_plot_points < 100)
    throw Error("run report: max_plot_points", fmt::format("{} is too few (>= 100)", o.max_plot_points));
  if (o.max_loop_points < 100)
    throw Error("run report: max_loop_points", fmt::format("{} is too few (>= 100)", o.max_loop_points));
  if (!(o.welch_segment_s > 0.0 && o.welch_segment_s <= 3600.0))
    throw Error("run report: welch_segment_s", fmt::format("{} s is out of range (0, 3600]", o.welch_segment_s));
  if (!(o.min_coherence >= 0.0 && o.min_coherence <= 1.0))
    throw Error("run report: min_coherence", fmt::format("{} is out of range [0, 1]", o.min_coherence));
  if (!(o.band_db > 0.0 && o.band_db <= 200.0))
    throw Error("run report: band_db", fmt::format("{} dB is out of range (0, 200]", o.band_db));
}

/// The figures a report draws, and the notes on those it does not.
struct DrawnFigures {
  std::vector<PageFigure> drawn;        ///< in page order, each drawable
  std::vector<std::string> notes;       ///< why a figure is missing
  std::string frequency_summary;        ///< G_yr's row of the results table ("" if none)
  std::string benchmark_html;           ///< the J1-J9 table (scenarios with structure.reference_file)
};

DrawnFigures ChooseFigures(const RunData& d, const RunReportOptions& o) {
  DrawnFigures out;
  std::vector<PageFigure> figures;
  if (d.signals.steps() >= 2) {
    figures.push_back(run_figures::TrackingError(d.signals, o));  // first: what a tracking test is judged by
    figures.push_back(run_figures::TimeHistories(d.signals, o));
    if (auto rt = run_figures::RealtimeLatency(d, o)) figures.push_back(*rt);
    figures.push_back(run_figures::Loops(d.signals, o));
    if (auto ad = run_figures::Adaptation(d.signals, o)) figures.push_back(*ad);
    run_figures::FrequencyFigures ff = run_figures::Frequency(d.signals, o);
    if (ff.spectra) figures.push_back(*ff.spectra);
    if (ff.gyr) figures.push_back(*ff.gyr);
    out.frequency_summary = ff.summary_html;
    out.notes = ff.notes;
    run_figures::BenchmarkSection bs = run_figures::Benchmark(d, o);
    if (bs.figure) figures.push_back(*bs.figure);
    out.benchmark_html = bs.table_html;
    if (!bs.note.empty()) out.notes.push_back(bs.note);
  } else {
    out.notes.push_back(fmt::format("no figures: the log holds {} complete step(s)", d.signals.steps()));
  }
  for (auto& pf : figures) {
    if (run_figures::Drawable(pf.figure)) {
      out.drawn.push_back(std::move(pf));
    } else {
      out.notes.push_back(fmt::format("no figure {}: a panel has no finite value (the run diverged?)", pf.figure.name));
    }
  }
  return out;
}

/// Draws the figures into fig_dir (one gnuplot process per figure, all at once) after removing an
/// earlier report's figures that this one does not draw; the PNGs in page order.
std::vector<fs::path> DrawFigures(const std::vector<PageFigure>& drawn, const fs::path& fig_dir) {
  std::error_code ec;
  for (const char* stale :
       {"time_histories", "tracking_error", "realtime", "loops", "adaptation", "spectra", "gyr", "benchmark"}) {
    if (std::any_of(drawn.begin(), drawn.end(), [&](const PageFigure& pf) { return pf.figure.name == stale; }))
      continue;
    for (const char* ext : {".png", ".dat", ".gp"}) fs::remove(fig_dir / (std::string(stale) + ext), ec);
  }
  std::vector<std::future<io::PlotFiles>> jobs;
  for (const auto& pf : drawn) jobs.push_back(std::async(std::launch::async, [&pf, &fig_dir] { return io::Plot(pf.figure, fig_dir); }));
  std::vector<fs::path> pngs;
  for (auto& j : jobs) pngs.push_back(j.get().png);
  return pngs;
}

/// The banner: green if the run completed, else its warnings (the first one the headline if it failed).
std::string Banner(const ReportFiles& files, bool failed) {
  if (files.warnings.empty()) {
    return "<div class=\"banner ok\" id=\"banner\"><p>The run completed: " + std::to_string(files.steps) + " of " +
           std::to_string(files.steps_planned) + " steps.</p></div>\n";
  }
  std::string h = std::string("<div class=\"banner ") + (failed ? "failed" : "note") + "\" id=\"banner\">\n";
  for (std::size_t i = 0; i < files.warnings.size(); ++i) {
    const std::string line = HtmlEscape(files.warnings[i]);
    h += failed && i == 0 ? "<p><strong>" + line + "</strong></p>\n" : "<p>" + line + "</p>\n";
  }
  return h + "</div>\n";
}

/// The "Figures" section: the notes, then each figure with its caption.
std::string FiguresSection(const DrawnFigures& f, const std::vector<fs::path>& pngs) {
  std::string h = "<h2 id=\"figures\">Figures</h2>\n";
  if (!f.notes.empty()) {
    h += "<div class=\"banner note\">\n";
    for (const auto& n : f.notes) h += "<p>" + HtmlEscape(n) + "</p>\n";
    h += "</div>\n";
  }
  for (std::size_t i = 0; i < f.drawn.size(); ++i) {
    const std::string png = pngs[i].filename().string();
    h += FigureHtml(f.drawn[i].figure.name, f.drawn[i].heading, png, f.drawn[i].figure.width_px, f.drawn[i].caption_html);
  }
  return h;
}

/// The page's title: the scenario's name, and the overrides a `--set` run was made with (its
/// scenario.toml's first line, "# FILE with --set K=V ..."), so a variant is not named as its base.
std::string RunTitle(const RunData& d) {
  std::string name = d.scenario ? d.scenario->run.name : d.run_dir.filename().string();
  const std::string first = d.scenario_toml.substr(0, d.scenario_toml.find('\n'));
  if (const auto with = first.find(" with --set "); first.rfind("# ", 0) == 0 && with != std::string::npos) {
    std::string sets = first.substr(with + 6);  // "--set a=1 --set b=2"
    for (std::size_t at; (at = sets.find("--set ")) != std::string::npos;) sets.erase(at, 6);
    name += " (" + sets + ")";
  }
  return name;
}

}  // namespace

std::optional<signal::BenchmarkCriteria> BenchmarkCriteriaOf(const RunData& d) {
  if (!d.summary.is_object() || !d.summary.contains("benchmark_criteria")) return std::nullopt;
  const nlohmann::json& b = d.summary["benchmark_criteria"];
  const auto num = [](const nlohmann::json& j, const char* key) {
    return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
  };
  signal::BenchmarkCriteria c;
  c.J1_ms = num(b, "J1_ms");
  const char* keys[] = {"J2_pct", "J3_pct", "J4_pct", "J5_pct", "J6_pct", "J7_pct", "J8_pct", "J9_pct"};
  double* fields[] = {&c.J2_pct, &c.J3_pct, &c.J4_pct, &c.J5_pct, &c.J6_pct, &c.J7_pct, &c.J8_pct, &c.J9_pct};
  for (int i = 0; i < 8; ++i) *fields[i] = num(b, keys[i]);
  c.lag_samples = b.contains("lag_samples") && b["lag_samples"].is_number_integer() ? b["lag_samples"].get<int>() : -1;
  if (b.contains("floors") && b["floors"].is_array())
    for (const auto& f : b["floors"])
      c.floors.push_back({f.value("floor", 0), num(f, "std_pct"), num(f, "max_pct")});
  return c;
}

RunData LoadRunData(const fs::path& run_dir) {
  const fs::path log_path = io::RunFolderLog(run_dir);
  std::error_code ec;
  RunData d;
  d.run_dir = run_dir;

  const fs::path summary_path = run_dir / "summary.json";
  if (fs::is_regular_file(summary_path, ec)) {
    try {
      d.summary = nlohmann::json::parse(Slurp(summary_path));
      if (!d.summary.is_object()) throw Error(summary_path.string(), "not a JSON object");
    } catch (const std::exception& e) {
      d.summary = nullptr;
      d.summary_error = fmt::format("{}: unreadable ({})", summary_path.string(), e.what());
    }
  } else {
    d.summary_error = "no summary.json in the run folder (the supervisor did not write it)";
  }
  // scenario.toml holds the bytes that ran; files it names are relative to the folder of the file
  // that ran (summary.json's "scenario"), so it is parsed as that file if it does not load here.
  const fs::path scenario_path = run_dir / "scenario.toml";
  if (fs::is_regular_file(scenario_path, ec)) {
    d.scenario_toml = Slurp(scenario_path);
    try {
      d.scenario = scenario::LoadScenario(scenario_path.string());
    } catch (const std::exception& e) {
      d.scenario_error = e.what();
      const std::string ran = run_tables::JsonText(d.summary, "scenario");
      if (!ran.empty()) {
        try {
          d.scenario = scenario::ParseScenario(d.scenario_toml, ran);
          d.scenario_error.clear();
        } catch (const std::exception&) {
          // keep the first error: it names the run folder's file
        }
      }
    }
  }

  const io::RunLog log = io::ReadRunLog(log_path.string());
  double dt_s = log.StepS();
  if (dt_s <= 0.0 && d.scenario) dt_s = d.scenario->run.dt_s;
  if (!(dt_s > 0.0))
    throw Error(log_path.string(), "no step size: no handshake in the log carries dt_s and scenario.toml does not load");
  if (d.scenario && std::abs(d.scenario->run.dt_s - dt_s) > 1e-9 * dt_s)
    d.notes.push_back(fmt::format("scenario.toml says dt_s = {:g} s but the log's handshake {:g} s (the log's is used)",
                                  d.scenario->run.dt_s, dt_s));
  d.signals = io::SignalsFromRunLog(log, dt_s);
  d.metrics = io::ComputeMetrics(log);
  d.steps_planned = log.n_steps > 0 ? log.n_steps : (d.scenario ? d.scenario->steps() : d.metrics.steps);
  d.log_complete = log.Complete();
  d.truncation_reason = log.TruncationReason();
  d.abort_reason = log.AbortReason();
  if (d.summary.is_object()) {
    if (const auto st = run_tables::JsonNumber(d.summary, "steps"); st && static_cast<std::int64_t>(*st) != d.metrics.steps)
      d.notes.push_back(fmt::format("summary.json says {} steps but the log holds {} complete steps (the log was "
                                    "changed after the run?)",
                                    static_cast<std::int64_t>(*st), d.metrics.steps));
    const std::string sha = run_tables::JsonText(d.summary, "scenario_sha256");
    if (!sha.empty() && !d.scenario_toml.empty() && scenario::Sha256Hex(d.scenario_toml) != sha)
      d.notes.push_back("scenario.toml differs from the scenario that ran (its SHA-256 is not summary.json's "
                        "scenario_sha256): it was changed after the run");
  }
  return d;
}

ReportFiles WriteRunReport(const RunData& d, const RunReportOptions& o) {
  CheckOptions(o);
  if (!io::GnuplotAvailable(o.gnuplot))
    throw Error("", fmt::format("gnuplot is not installed (no '{}' on PATH): install it with `apt-get install "
                                "gnuplot-nox` and run again (nothing was written)",
                                o.gnuplot));
  const fs::path out = o.out_dir.empty() ? d.run_dir : o.out_dir;
  const fs::path fig_dir = out / "figures";
  std::error_code ec;
  fs::create_directories(fig_dir, ec);
  if (ec) throw Error(fig_dir.string(), "cannot create: " + ec.message());

  ReportFiles files;
  files.html = out / "report.html";
  files.steps = static_cast<std::int64_t>(d.signals.steps());
  files.steps_planned = d.steps_planned;
  files.complete = d.log_complete;
  bool failed = false;
  files.warnings = run_tables::Warnings(d, &failed);
  const DrawnFigures figures = ChooseFigures(d, o);
  files.figures = DrawFigures(figures.drawn, fig_dir);

  const std::string name = RunTitle(d);
  std::string h = HtmlHead("rths run report: " + name);
  h += "<h1>Run report: " + HtmlEscape(name) + "</h1>\n";
  h += "<p class=\"where\">" + HtmlEscape(fs::absolute(d.run_dir).lexically_normal().string()) +
       " &mdash; written by <code>rths report</code> from log.lcm, summary.json and scenario.toml</p>\n";
  h += Banner(files, failed);
  h += "<h2 id=\"results\">Results</h2>\n<table>\n" + run_tables::MetricsTable(d) + figures.frequency_summary +
       "</table>\n";
  if (!figures.benchmark_html.empty()) h += "<h2 id=\"criteria\">Benchmark criteria J1-J9</h2>\n" + figures.benchmark_html;
  h += run_tables::RealtimeTable(d.summary);
  h += "<h2 id=\"scenario\">Scenario</h2>\n<table>\n" + run_tables::ScenarioTable(d) + "</table>\n";
  if (!d.scenario_toml.empty()) {
    h += "<details><summary>scenario.toml (SHA-256 " + scenario::Sha256Hex(d.scenario_toml) + ")</summary>\n<pre>" +
         HtmlEscape(d.scenario_toml) + "</pre></details>\n";
  }
  h += FiguresSection(figures, files.figures);
  h += "<p class=\"where\">Units: mm, mm/s, kN, A, s. Eq. 31: RMS of r - y over the RMS of r, in %. Method: "
       "docs/report.md.</p>\n</body></html>\n";
  for (const auto& n : figures.notes) files.warnings.push_back(n);
  WriteFileAtomically(files.html, h);
  return files;
}

ReportFiles WriteRunReport(const fs::path& run_dir, const RunReportOptions& options) {
  CheckOptions(options);
  return WriteRunReport(LoadRunData(run_dir), options);
}

}  // namespace rths::report
