// lib/report/run_report + rths-report (docs/report.md): the report of a short memq run has every
// figure, each a real picture (decoded by Octave: pixel variance), the page names them and quotes
// summary.json's Eq. 31 value, and a headless Chromium renders it to a non-blank screenshot with
// the figures in it. Also: a truncated log, a safety stop, no gnuplot, the tool's exit codes.
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/exit_code.h"
#include "core/error.h"
#include "report/html.h"
#include "report/run_report.h"
#include "plot_data.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths_test::RunCli;
using rths_test::TempDir;
using rths_test::Slurp;
using rths_test::WriteScenario;

namespace {

/// 4 s of the default SDOF (8000 steps at 2 kHz), the damper at 1 A for the first 2 s, then at 0 A.
const char* kScenario = R"(
[run]
name = "report_test"
dt_s = 0.0005
duration_s = 4.0
[structure]
mass_kg = 20000.0
frequency_hz = 5.0
damping_ratio = 0.02
[structure.ground]
kind = "blwn"
band_hz = 30.0
rms_mm_s2 = 1500.0
seed = 3
[controller]
kind = "ff"
[plant]
actuator = "avg"
[semiactive]
mode = "pulse"
pulse_hz = 0.25
max_current_A = 1.0
[lockstep]
stall_budget_s = 5.0
handshake_timeout_s = 10.0
)";

nlohmann::json ReadJson(const fs::path& p) { return nlohmann::json::parse(Slurp(p)); }

/// Runs a shell command; its stdout and stderr into *output; returns its exit code.
int Shell(const std::string& cmd, std::string* output) {
  const fs::path txt = fs::temp_directory_path() / ("rths_report_sh_" + std::to_string(::getpid()) + ".txt");
  const int status = std::system((cmd + " > '" + txt.string() + "' 2>&1").c_str());
  *output = Slurp(txt);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// A run of kScenario (+ extra TOML) by `rths-run --transport memq` into dir/run; its exit code.
int MakeRun(const fs::path& dir, const std::string& extra = "") {
  const fs::path scenario = WriteScenario(dir, std::string(kScenario) + extra);
  std::string out;
  const int code = RunCli(scenario.string() + " --transport memq --out " + (dir / "run").string(), &out);
  INFO(out);
  CHECK(fs::exists(dir / "run" / "log.lcm"));
  return code;
}

/// The number in the page's <td id="ID">NUMBER ...</td>.
double CellNumber(const std::string& html, const std::string& id) {
  const std::string tag = "<td id=\"" + id + "\">";
  const auto p = html.find(tag);
  REQUIRE(p != std::string::npos);
  return std::stod(html.substr(p + tag.size()));
}

/// Per image, from Octave's imread: the standard deviation of every pixel value (0-255 scale), the
/// fraction of pixels that are not near-white, and the pixels near #1f77b4 (the blue of u).
struct ImageStats {
  double stddev = 0.0, ink_fraction = 0.0;
  long blue_pixels = 0;
};
std::map<std::string, ImageStats> OctaveImageStats(const std::vector<fs::path>& images) {
  std::string script;
  for (const auto& p : images)
    script += "x = double(imread('" + p.string() + "')); if size(x, 3) == 1, x = repmat(x, [1 1 3]); end; "
              "x = x(:, :, 1:3); s = std(x(:)); ink = mean(min(x, [], 3)(:) < 200); "
              "b = abs(x(:,:,1) - 31) < 30 & abs(x(:,:,2) - 119) < 30 & abs(x(:,:,3) - 180) < 30; "
              "printf('IMG %s %.6g %.6g %d\\n', '" + p.filename().string() + "', s, ink, sum(b(:))); ";
  std::string out;
  const int code = Shell("octave-cli --no-gui --norc --quiet --eval \"" + script + "\"", &out);
  INFO(out);
  CHECK(out.find("IMG") != std::string::npos);
  (void)code;  // octave may complain on exit after printing; the lines are what count
  std::map<std::string, ImageStats> stats;
  std::istringstream in(out);
  std::string word;
  while (in >> word) {
    if (word != "IMG") continue;
    std::string name;
    ImageStats s;
    in >> name >> s.stddev >> s.ink_fraction >> s.blue_pixels;
    stats[name] = s;
  }
  return stats;
}

const std::vector<std::string> kFigures = {"tracking_error", "time_histories", "loops", "spectra", "gyr"};

}  // namespace

TEST_CASE("MinMaxDecimate keeps every peak, in time order; CentralDifference; HtmlEscape") {
  std::vector<double> x(10000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.01 * static_cast<double>(i));
  x[1234] = 50.0;
  x[8765] = -40.0;
  const auto idx = rths::report::MinMaxDecimate(x, 400);
  CHECK(idx.size() <= 400);
  CHECK(idx.size() >= 300);
  for (std::size_t i = 1; i < idx.size(); ++i) CHECK(idx[i] > idx[i - 1]);
  CHECK(std::find(idx.begin(), idx.end(), 1234u) != idx.end());
  CHECK(std::find(idx.begin(), idx.end(), 8765u) != idx.end());
  CHECK(rths::report::MinMaxDecimate(std::vector<double>(50, 1.0), 400).size() == 50);
  CHECK(rths::report::HtmlEscape("a<b & \"c\"") == "a&lt;b &amp; &quot;c&quot;");
}

TEST_CASE("the report of a run: five real figures, the Eq. 31 value of summary.json, a page Chromium renders") {
  const auto dir = TempDir("report_full");
  REQUIRE(MakeRun(dir) == 0);
  const fs::path run = dir / "run";
  const auto files = rths::report::WriteRunReport(run);
  CHECK(files.html == run / "report.html");
  CHECK(files.complete);
  CHECK(files.steps == 8000);
  CHECK(files.steps_planned == 8000);
  CHECK(files.warnings.empty());
  REQUIRE(files.figures.size() == kFigures.size());

  const std::string html = Slurp(files.html);
  CHECK(html.find("class=\"banner ok\"") != std::string::npos);
  for (std::size_t i = 0; i < kFigures.size(); ++i) {
    CAPTURE(kFigures[i]);
    CHECK(files.figures[i] == run / "figures" / (kFigures[i] + ".png"));
    const std::string png = Slurp(files.figures[i]);
    CHECK(png.size() > 10000);
    CHECK(png.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
    CHECK(html.find("src=\"figures/" + kFigures[i] + ".png\"") != std::string::npos);
  }
  // The page quotes what summary.json says (4 significant digits), and the scenario.
  const auto summary = ReadJson(run / "summary.json");
  const double nrmse = summary.at("tracking_nrmse_pct").get<double>();
  CHECK(nrmse > 0.0);
  CHECK(CellNumber(html, "tracking_nrmse_pct") == doctest::Approx(nrmse).epsilon(1e-3));
  CHECK(CellNumber(html, "peak_force_kN") == doctest::Approx(summary.at("peak_force_kN").get<double>()).epsilon(1e-3));
  CHECK(html.find("completed (exit code 0)") != std::string::npos);
  CHECK(html.find("<details><summary>scenario.toml") != std::string::npos);
  CHECK(html.find("name = &quot;report_test&quot;") != std::string::npos);
  CHECK(html.find("pulse, max 1 A") != std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("http") == std::string::npos);  // nothing from the network

  // Each PNG is a picture, not an empty frame: its pixels vary and some are ink.
  rths_test::RequireTool("octave-cli", "octave");
  const auto stats = OctaveImageStats(files.figures);
  for (const auto& name : kFigures) {
    CAPTURE(name);
    REQUIRE(stats.count(name + ".png") == 1);
    const auto& s = stats.at(name + ".png");
    CHECK(s.stddev > 10.0);
    CHECK(s.ink_fraction > 0.01);
  }
  CHECK(stats.at("time_histories.png").blue_pixels > 500);  // u is drawn
  CHECK(stats.at("gyr.png").blue_pixels < 20);               // no sensor noise: the coherence is 1, not drawn

  // The page in a headless browser: not blank, and the figures load (their blue is on screen).
  rths_test::RequireTool("chromium", "chromium");
  const fs::path shot = dir / "screenshot.png";
  std::string out;
  const int code = Shell("timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir='" +
                             (dir / "chromium").string() + "' --screenshot='" + shot.string() +
                             "' --window-size=1200,2000 'file://" + fs::absolute(files.html).string() + "'",
                         &out);
  INFO(out);
  CHECK(code == 0);
  REQUIRE(fs::exists(shot));
  const auto page = OctaveImageStats({shot});
  REQUIRE(page.count("screenshot.png") == 1);
  CHECK(page.at("screenshot.png").stddev > 10.0);
  CHECK(page.at("screenshot.png").ink_fraction > 0.01);
  CHECK(page.at("screenshot.png").blue_pixels > 200);
}

TEST_CASE("a truncated log without summary.json: its complete steps, and the page says the run did not finish") {
  const auto dir = TempDir("report_truncated");
  REQUIRE(MakeRun(dir) == 0);
  const fs::path run = dir / "run";
  fs::remove(run / "summary.json");
  const auto size = fs::file_size(run / "log.lcm");
  fs::resize_file(run / "log.lcm", size / 2 + 7);  // cut in the middle of an event
  rths::report::RunReportOptions o;
  o.out_dir = dir / "report";
  const auto files = rths::report::WriteRunReport(run, o);
  CHECK(files.html == dir / "report" / "report.html");
  CHECK_FALSE(files.complete);
  CHECK(files.steps > 1000);
  CHECK(files.steps < 8000);
  CHECK(files.steps_planned == 8000);
  CHECK(files.figures.size() == kFigures.size());
  const std::string html = Slurp(files.html);
  CHECK(html.find("class=\"banner failed\"") != std::string::npos);
  CHECK(html.find("<p><strong>This run did not finish (log.lcm: truncated") != std::string::npos);
  CHECK(html.find("Its log holds " + std::to_string(files.steps) + " complete step(s) of 8000 planned") !=
        std::string::npos);
  CHECK(html.find("no summary.json") != std::string::npos);
  CHECK(!fs::exists(run / "report.html"));  // --out: nothing in the run folder
  // The Eq. 31 value is the log's over its complete steps.
  const auto data = rths::report::LoadRunData(run);
  CHECK(CellNumber(html, "tracking_nrmse_pct") == doctest::Approx(data.metrics.tracking_nrmse_pct).epsilon(1e-3));
}

TEST_CASE("a run stopped by the safety monitor: status, exit code 6 and the reason on top") {
  const auto dir = TempDir("report_safety");
  REQUIRE(MakeRun(dir, "[safety]\nmax_error_mm = 0.01\n") == 6);
  const auto files = rths::report::WriteRunReport(dir / "run");
  CHECK_FALSE(files.complete);
  const std::string html = Slurp(files.html);
  CHECK(html.find("class=\"banner failed\"") != std::string::npos);
  CHECK(html.find("<p><strong>This run did not finish: stopped by the safety monitor (exit code 6): ") !=
        std::string::npos);
  CHECK(html.find("(safety.max_error_mm)") != std::string::npos);
  CHECK(html.find("<td id=\"status\">stopped by the safety monitor (exit code 6)") != std::string::npos);
  CHECK(files.steps < 8000);
  CHECK(files.figures.size() == kFigures.size());  // the steps before the stop are drawn
}

TEST_CASE("a paced run: the real-time figures of summary.json on the page") {
  const auto dir = TempDir("report_realtime");
  // 0.25 s paced at 2 kHz (the 4 s of kScenario would be long for a test).
  std::string text = std::string(kScenario) + "[realtime]\nenabled = true\n";
  text.replace(text.find("duration_s = 4.0"), std::string("duration_s = 4.0").size(), "duration_s = 0.25");
  const fs::path scenario = WriteScenario(dir, text);
  std::string out;
  REQUIRE(RunCli(scenario.string() + " --transport memq --out " + (dir / "run").string(), &out) == 0);
  const auto files = rths::report::WriteRunReport(dir / "run");
  const std::string html = Slurp(files.html);
  const auto rt = ReadJson(dir / "run" / "summary.json").at("realtime");
  CHECK(html.find("<h2 id=\"realtime\">Real time</h2>") != std::string::npos);
  CHECK(html.find("paced at</th><td>2000 Hz") != std::string::npos);
  CHECK(html.find(fmt::format("<td id=\"latency\">p50 {:.0f} us", rt.at("latency_p50_us").get<double>())) !=
        std::string::npos);
  CHECK(html.find(fmt::format("<td id=\"deadline_misses\">{} of {} steps", rt.at("deadline_misses").get<long>(),
                              rt.at("steps").get<long>())) != std::string::npos);
}

TEST_CASE("no gnuplot: a clear error, and nothing written") {
  const auto dir = TempDir("report_nognuplot");
  REQUIRE(MakeRun(dir) == 0);
  rths::report::RunReportOptions o;
  o.gnuplot = "rths-no-such-gnuplot";
  o.out_dir = dir / "report";
  CHECK_THROWS_WITH_AS(rths::report::WriteRunReport(dir / "run", o),
                       doctest::Contains("gnuplot is not installed (no 'rths-no-such-gnuplot' on PATH): install it"),
                       rths::Error);
  CHECK_FALSE(fs::exists(dir / "report"));
  o.gnuplot = "gnuplot";
  o.min_coherence = 1.5;
  CHECK_THROWS_WITH_AS(rths::report::WriteRunReport(dir / "run", o), doctest::Contains("[0, 1]"), rths::Error);
}

TEST_CASE("rths report: exit codes, help, the output line") {
  const auto dir = TempDir("report_cli");
  const std::string tool = std::string(RTHS_BIN_DIR) + "/rths-report";
  std::string out;
  CHECK(Shell(tool + " " + (dir / "no_such_run").string(), &out) == 2);
  CHECK(out.find("rths report: ") != std::string::npos);
  CHECK(out.find("no such run folder") != std::string::npos);
  CHECK(Shell(tool + " " + dir.string(), &out) == 2);
  CHECK(out.find("no log.lcm") != std::string::npos);
  CHECK(Shell(tool, &out) == 2);
  CHECK(Shell(tool + " --no-such-option", &out) == 2);
  CHECK(out.find("Run with --help") != std::string::npos);
  CHECK(Shell(tool + " --help", &out) == 0);
  CHECK(out.find("rths report") != std::string::npos);  // tools/cli.h: the command as the user types it
  CHECK(out.find("bin/rths-") == std::string::npos);
  for (const char* opt : {"--out", "--max-plot-points", "--welch-segment-s", "--min-coherence", "--band-db", "--gnuplot"})
    CHECK(out.find(opt) != std::string::npos);
  CHECK(out.find("0.9") != std::string::npos);  // defaults shown

  REQUIRE(MakeRun(dir) == 0);
  CHECK(Shell(tool + " " + (dir / "run").string() + " --min-coherence 2", &out) == 2);
  CHECK(Shell(tool + " " + (dir / "run").string() + " --gnuplot rths-no-such-gnuplot", &out) == rths::kExitInternal);  // the page could not be made (core/exit_code.h)
  CHECK(out.find("rths report: ") != std::string::npos);
  CHECK(out.find("gnuplot is not installed") != std::string::npos);
  CHECK(Shell(tool + " " + (dir / "run").string() + " --out " + (dir / "rep").string(), &out) == 0);
  INFO(out);
  CHECK(out.find("8000 of 8000 steps -> " + (dir / "rep" / "report.html").string() + " (5 figures)") !=
        std::string::npos);
  CHECK(fs::exists(dir / "rep" / "figures" / "gyr.png"));
}

TEST_CASE("a reviewer's figures: a constant current is a line of text, the spectra show the band of r, a flat "
          "coherence is left out, a paced run that missed deadlines is not green") {
  // kScenario with the current held at 0 A and no sensor noise: a deterministic run.
  const auto dir = TempDir("report_reviewer");
  REQUIRE(MakeRun(dir, "") == 0);  // kScenario's pulse current, for the spectra
  const fs::path run = dir / "run";
  const fs::path dir0 = TempDir("report_reviewer_const");
  std::string text0 = kScenario;
  const std::string pulse = "mode = \"pulse\"";
  text0.replace(text0.find(pulse), pulse.size(), "mode = \"passive_off\"");
  const fs::path scenario0 = WriteScenario(dir0, text0);
  std::string out;
  REQUIRE_MESSAGE(RunCli(scenario0.string() + " --transport memq --out " + (dir0 / "run").string(), &out) == 0, out);

  const auto files0 = rths::report::WriteRunReport(dir0 / "run");
  const std::string html0 = Slurp(files0.html);
  CHECK(html0.find("The damper current is constant over the run: commanded 0 A, effective 0 A (not drawn).") !=
        std::string::npos);
  const std::string gp0 = Slurp(dir0 / "run" / "figures" / "time_histories.gp");
  CHECK(gp0.find("current [A]") == std::string::npos);
  CHECK(gp0.find("force [kN]") != std::string::npos);
  // The pulsed run keeps its current panel.
  const auto files = rths::report::WriteRunReport(run);
  CHECK(Slurp(run / "figures" / "time_histories.gp").find("current [A]") != std::string::npos);

  // Spectra: x from 0 to 1.5 x the top of r's 40 dB band (a 0-30 Hz excitation of a 5 Hz structure:
  // tens of Hz, not the 1 kHz Nyquist), y over at most 8 decades (+ the factor-2 margins).
  const std::string sp = Slurp(run / "figures" / "spectra.gp");
  const auto xr = sp.find("set xrange [");
  REQUIRE(xr != std::string::npos);
  const double x_hi = std::stod(sp.substr(sp.find(':', xr) + 1));
  CHECK(x_hi > 10.0);
  CHECK(x_hi < 300.0);
  const auto yr = sp.find("set yrange [");
  REQUIRE(yr != std::string::npos);
  const double y_lo = std::stod(sp.substr(yr + 12)), y_hi = std::stod(sp.substr(sp.find(':', yr) + 1));
  CHECK(std::log10(y_hi / y_lo) <= 8.0 + std::log10(4.0) + 1e-9);
  CHECK(sp.find("set logscale x") == std::string::npos);

  // Without sensor noise the coherence is 1 over the band: not drawn, and the caption says why;
  // with noise on y it falls, and is drawn.
  const std::string gyr0 = Slurp(dir0 / "run" / "figures" / "gyr.gp");
  CHECK(gyr0.find("coherence [-]") == std::string::npos);
  CHECK(html0.find("The coherence is not drawn: it is 1 to within 0.001 over the whole band") != std::string::npos);
  const fs::path dirn = TempDir("report_reviewer_noise");
  std::string text_n = kScenario;
  text_n.replace(text_n.find("actuator = \"avg\""), 16, "actuator = \"avg\"\nnoise_y_mm_rms = 0.05");
  const fs::path scenario_n = WriteScenario(dirn, text_n);
  REQUIRE_MESSAGE(RunCli(scenario_n.string() + " --transport memq --out " + (dirn / "run").string(), &out) == 0, out);
  rths::report::WriteRunReport(dirn / "run");
  CHECK(Slurp(dirn / "run" / "figures" / "gyr.gp").find("coherence [-]") != std::string::npos);

  // A paced run that missed deadlines (summary.json's figures): a note in the banner, not green.
  rths::report::RunData d = rths::report::LoadRunData(dir0 / "run");
  d.summary["realtime"] = {{"paced", true}, {"steps", 8000}, {"deadline_misses", 94}, {"miss_fraction", 94.0 / 8000},
                           {"max_consecutive_misses", 44}, {"first_miss_step", 1200}, {"latency_max_us", 15600.0}};
  rths::report::RunReportOptions o;
  o.out_dir = dir0 / "paced";
  const auto paced = rths::report::WriteRunReport(d, o);
  const std::string html_paced = Slurp(paced.html);
  CHECK(html_paced.find("class=\"banner ok\"") == std::string::npos);
  CHECK(html_paced.find("NOT real time: this paced run missed 94 of 8000 deadlines (1.18 %); the longest stretch was "
                        "44 steps in a row (22 ms), the largest step latency 15.6 ms, the first miss at step 1200.") !=
        std::string::npos);
  CHECK_FALSE(fs::exists(dir0 / "paced" / "figures" / "realtime.png"));  // no windows in that summary

  // A real paced run: the clock keeps the largest latency and the misses of every 0.1 s window,
  // and the report draws them over the run with the windows that missed marked.
  const fs::path dirp = TempDir("report_reviewer_paced");
  REQUIRE_MESSAGE(RunCli(scenario0.string() + " --transport memq --realtime --set run.duration_s=1 --out " +
                             (dirp / "run").string(),
                         &out) == 0,
                  out);
  auto sp_json = ReadJson(dirp / "run" / "summary.json");
  const auto& windows = sp_json["realtime"]["latency_windows"];
  CHECK(windows["window_steps"] == 200);
  REQUIRE(windows["max_us"].size() == 10);
  CHECK(windows["misses"].size() == 10);
  for (const auto& v : windows["max_us"]) CHECK(v.get<double>() > 0.0);
  rths::report::RunData dp = rths::report::LoadRunData(dirp / "run");
  dp.summary["realtime"]["latency_windows"]["misses"][4] = 3;  // as if window 4 had missed 3 deadlines
  rths::report::RunReportOptions op;
  op.out_dir = dirp / "report";
  const auto paced_files = rths::report::WriteRunReport(dp, op);
  CHECK(fs::file_size(dirp / "report" / "figures" / "realtime.png") > 10000);
  const std::string gp = Slurp(dirp / "report" / "figures" / "realtime.gp");
  CHECK(gp.find("windows with deadline misses") != std::string::npos);
  int missed_windows = 0;  // window 4, and any the real run missed in
  for (const auto& m : dp.summary["realtime"]["latency_windows"]["misses"]) missed_windows += m.get<int>() > 0 ? 1 : 0;
  CHECK(Slurp(paced_files.html).find(fmt::format("{} window(s) held deadline misses (marked)", missed_windows)) !=
        std::string::npos);
}

TEST_CASE("a benchmark run's report: the smaller error curve drawn over the larger, G_yr with a title") {
  const auto dir = TempDir("report_benchmark_figures");
  std::string out;
  REQUIRE_MESSAGE(RunCli(std::string(RTHS_SOURCE_DIR) + "/scenarios/benchmark/case2_example.toml --transport memq "
                         "--skip-space-check --set run.duration_s=12 --out " + (dir / "run").string(),
                         &out) == 0,
                  out);
  rths::report::WriteRunReport(dir / "run");
  const fs::path figs = dir / "run" / "figures";
  // The errors x_m - x_t (J2) and x_m - x_r,1 (J4) overlap: the one of larger RMS first, beneath.
  const auto errors = rths_test::PanelCurves(rths_test::ReadPlotData(figs / "benchmark.dat"), 2);
  REQUIRE(errors.size() == 2);
  auto rms = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x * x;
    return std::sqrt(s / static_cast<double>(v.size()));
  };
  CHECK(rms(errors[0].y) > rms(errors[1].y));
  CHECK(errors[0].title.find("x_r,1") != std::string::npos);  // J4 > J2 for the example controller
  // G_yr has a title over its panels, and each panel its own.
  const std::string gyr = Slurp(figs / "gyr.gp");
  const auto multiplot = gyr.find("set multiplot layout ");
  REQUIRE(multiplot != std::string::npos);
  CHECK(gyr.substr(multiplot, gyr.find('\n', multiplot) - multiplot).find(",1 title 'G_yr = Y / R: ") != std::string::npos);
  CHECK(gyr.find("set title 'Magnitude'") != std::string::npos);
  CHECK(gyr.find("set title 'Phase (unwrapped)'") != std::string::npos);
  // The spectra have a title of their own in the PNG too, not only the page's heading.
  CHECK(Slurp(figs / "spectra.gp").find("title 'Power spectral densities of r (desired)") != std::string::npos);
  // The force-velocity loop's velocity is the low-passed derivative of y, not its noisy central difference.
  CHECK(Slurp(figs / "loops.gp").find("y'' [mm/s] (low-passed at 50 Hz)") != std::string::npos);
  // Peaks off the frame (time histories: above and below only) and legends above the axes, where
  // they cover no curve; a loop's extremes off the frame on every side.
  for (const char* name : {"time_histories.gp", "tracking_error.gp"}) {
    CAPTURE(name);
    const std::string gp = Slurp(figs / name);
    for (int p = 1; p <= 2; ++p) {
      CAPTURE(p);
      const std::string panel = rths_test::PanelScript(gp, p);
      CHECK(panel.find("set offsets graph 0, graph 0, graph 0.06, graph 0.06") != std::string::npos);
      CHECK((panel.find("set key off") != std::string::npos ||
             panel.find("set key on outside top center horizontal") != std::string::npos));
    }
  }
  const std::string loops = Slurp(figs / "loops.gp");
  CHECK(rths_test::PanelScript(loops, 1).find("set offsets graph 0.06, graph 0.06, graph 0.06, graph 0.06") !=
        std::string::npos);
}
