#pragma once
/// @file A report for every run (`rths report RUN_DIR`, `rths run --report`; docs/report.md): one
/// self-contained HTML page (no JavaScript, no network; relative links to PNG figures) with the
/// scenario, the summary metrics and the figures of a run folder written by `rths run`.
///
/// Everything is read from the run folder's log.lcm (io/run_log.h, io/run_signals.h), never from
/// signals.csv (which may be absent or decimated); summary.json adds what the log cannot know (how
/// the run ended, its exit code, link repairs, real-time figures), scenario.toml the settings.
/// A log that ends early (a run that stopped) is reported over its complete steps, and the page
/// says so at the top.
///
/// Figures (gnuplot, io/plot.h), in OUT/figures/:
///   tracking_error.png  e = r - y [mm] against t [s], and r, u, y over 0.25 s around the largest |e|
///   time_histories.png  r, u, y [mm]; f [kN]; damper current i_cmd, i_eff [A] against t [s] (a
///                       constant current is a line of the caption instead)
///   loops.png           force-displacement f(y) and force-velocity f(y') (run_figures::LoopVelocity)
///   spectra.png         Welch PSDs of r, y, e [mm^2/Hz] (signal/spectral.h) over the band that
///                       carries r, at most 8 decades (signal/spectrum_axes.h)
///   gyr.png             G_yr = Y/R by H1: magnitude [-], phase [deg] and coherence [-] (left out
///                       when it is 1 to within 1e-4: a noise-free run), limited to the excited
///                       band of r, points of low coherence masked
///   benchmark.png       scenarios with structure.reference_file (the RTHS benchmark, docs/benchmark.md):
///                       x_t = r, x_m = y and the reference's actuator floor x_r,a; x_m - x_t and
///                       x_m - x_r,a (the one of larger RMS beneath); each other floor x_n,i against
///                       x_r,i [mm] against t [s]. The page then also has the table of J1-J9
///                       (participants/benchmark_run.h).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "io/run_signals.h"
#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"

namespace rths::report {

/// How a run report is drawn.
struct RunReportOptions {
  /// Where report.html and figures/ go; empty = the run folder itself.
  std::filesystem::path out_dir;
  std::string gnuplot = "gnuplot";        ///< plotting program (a name on PATH or a path)
  /// Time-history curves longer than this are reduced to the minimum and maximum of each of
  /// max_plot_points / 2 buckets (peaks kept); the spectra always use every step. [points], >= 100
  std::size_t max_plot_points = 4000;
  /// Loops (f against y and y') are thinned by a stride to at most this many points. >= 100
  std::size_t max_loop_points = 8000;
  /// Welch segment length aimed at [s] (a power of two of steps near it, at most a quarter of the
  /// run, so at least 7 segments are averaged), (0, 3600].
  double welch_segment_s = 2.0;
  /// G_yr: points whose coherence gamma^2 is below this are masked, [0, 1].
  double min_coherence = 0.9;
  /// G_yr: the excited band of r is where its PSD is within this many dB of its peak, (0, 200].
  double band_db = 60.0;
};

/// What a run folder holds, decoded: the input of a report.
struct RunData {
  std::filesystem::path run_dir;
  io::RunSignals signals;                 ///< every complete step (from log.lcm)
  io::RunMetrics metrics;                 ///< Eq. 31 error and peaks over the complete steps
  std::int64_t steps_planned = 0;         ///< from the log's handshakes (or the scenario)
  bool log_complete = false;              ///< the log holds DONE and no cut-short event
  std::string truncation_reason;          ///< io::RunLog::TruncationReason() ("" if complete)
  std::string abort_reason;               ///< the ABORT reason in the log ("" if none)
  std::string scenario_toml;              ///< scenario.toml's text ("" if absent)
  std::optional<scenario::Scenario> scenario;  ///< parsed and validated, if it loads
  std::string scenario_error;             ///< why it did not ("" if it did or is absent)
  nlohmann::json summary;                 ///< summary.json (null if absent or unreadable)
  std::string summary_error;              ///< why it is null ("" if it was read)
  std::vector<std::string> notes;         ///< inconsistencies found while reading (shown on the page)
};

/// Reads a run folder: log.lcm (required), scenario.toml and summary.json (optional). dt comes
/// from the log's handshake (else the scenario). Throws rths::Error naming the folder or file if
/// the folder or its log.lcm does not exist, the log cannot be read, or no step size is known.
RunData LoadRunData(const std::filesystem::path& run_dir);

/// The benchmark's J1-J9 of a run as its summary.json holds them ("benchmark_criteria", written by
/// supervisor::RunSummary; a value that is null or absent is NaN); nullopt if it holds none.
std::optional<signal::BenchmarkCriteria> BenchmarkCriteriaOf(const RunData& d);

/// The files a report wrote, and what its page warns about.
struct ReportFiles {
  std::filesystem::path html;                    ///< OUT/report.html
  std::vector<std::filesystem::path> figures;    ///< OUT/figures/*.png, in page order
  std::int64_t steps = 0;                        ///< complete steps reported
  std::int64_t steps_planned = 0;                ///< steps the run planned
  bool complete = false;                         ///< the run finished and its log is whole
  std::vector<std::string> warnings;             ///< the page's banner lines (truncated, stopped, ...)
};

/// Writes report.html and figures/ for `data` into options.out_dir (or data.run_dir), replacing
/// an earlier report there. Throws rths::Error if the options are out of range, if gnuplot is
/// not installed ("install gnuplot: apt-get install gnuplot-nox"; checked before anything is
/// written), or if a figure or the page cannot be written.
ReportFiles WriteRunReport(const RunData& data, const RunReportOptions& options = {});

/// LoadRunData(run_dir), then WriteRunReport: the call for `rths run --report`.
ReportFiles WriteRunReport(const std::filesystem::path& run_dir, const RunReportOptions& options = {});

/// Indices of the samples of x that a plot keeps: every sample if x.size() <= max_points, else the
/// minimum and the maximum of each of max_points / 2 consecutive buckets, in time order (so the
/// envelope and every peak survive). max_points >= 4.
std::vector<std::size_t> MinMaxDecimate(const std::vector<double>& x, std::size_t max_points);

}  // namespace rths::report
