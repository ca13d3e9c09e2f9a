#pragma once
/// @file The figures of the run report (internal to report/run_report.cpp): each a gnuplot figure
/// with its heading and caption, from a run's decoded signals (io/run_signals.h). Units: mm, kN,
/// A, s; frequencies Hz.
#include <optional>
#include <string>
#include <vector>

#include "io/plot.h"
#include "io/run_signals.h"
#include "report/run_report.h"

namespace rths::report::run_figures {

/// One figure of the page: the gnuplot figure, its heading and its caption (HTML).
struct PageFigure {
  io::Figure figure;
  std::string heading;
  std::string caption_html;
};

/// A curve of y against x over the samples `idx` (line width 1.2).
io::Series Curve(const std::string& title, const std::string& color, const std::vector<double>& x,
                 const std::vector<double>& y, const std::vector<std::size_t>& idx);
/// A time history of y against t, min/max-decimated to max_points (every peak kept).
io::Series History(const std::string& title, const std::string& color, const std::vector<double>& t,
                   const std::vector<double>& y, std::size_t max_points);
/// An empty figure of a page: `name`, 1100 px wide, 300 px per row of panels, drawn by `gnuplot`.
io::Figure PageFrame(const std::string& name, const std::string& gnuplot);
/// Indices begin, begin + stride, ... < end, at most max_points of them (max_points >= 1).
std::vector<std::size_t> Strided(std::size_t begin, std::size_t end, std::size_t max_points);
/// Welch segment length [steps]: a power of two near segment_s / dt_s, at most n / 4, at least 32.
std::size_t SegmentLength(std::size_t n, double dt_s, double segment_s);

/// r, u, y [mm]; f (and the clipped-optimal desired force) [kN]; i_cmd, i_eff [A] against t [s].
PageFigure TimeHistories(const io::RunSignals& s, const RunReportOptions& o);
/// e = r - y [mm] over the run, and r, u, y over the 0.5 s around the largest |e|.
PageFigure TrackingError(const io::RunSignals& s, const RunReportOptions& o);
/// An adaptive controller's coefficients (columns a0, a1_s, ...), one panel each; nullopt for a
/// fixed controller.
std::optional<PageFigure> Adaptation(const io::RunSignals& s, const RunReportOptions& o);
/// A paced run's step latency over the run (summary.json realtime.latency_windows): the largest
/// latency of each 0.1 s window [ms], the deadline dt, and the windows with misses marked;
/// nullopt for an unpaced run or a summary without them.
std::optional<PageFigure> RealtimeLatency(const RunData& d, const RunReportOptions& o);
/// The damper's velocity in the force loops [mm/s]: the measured displacement y [mm] low-passed at
/// kLoopVelocityCutoffHz (2nd-order Butterworth forward and backward: zero phase) and differentiated
/// (diagnosis::SmoothMotion). Why not y's central difference: sensor noise on y (the benchmark's
/// 0.016 mm at 4096 Hz) becomes 46 mm/s RMS of velocity noise, more than the velocity, and the
/// force-velocity loop is a cloud; below the cut-off nothing changes (the loops of Fig. 11 of the
/// paper: a 0-30 Hz excitation loses < 0.1 % at 15 Hz). Why not the reference's velocity (rd_mm_s):
/// the loop is the specimen's, driven by where the actuator went, not where it was sent. Central
/// differences where y is not finite everywhere or has fewer than 4 samples.
std::vector<double> LoopVelocity(const std::vector<double>& y_mm, double dt_s);
/// Cut-off of LoopVelocity [Hz], where the step allows (LoopVelocityCutoffHz).
inline constexpr double kLoopVelocityCutoffHz = 50.0;
/// LoopVelocity's cut-off at step dt_s [Hz]: kLoopVelocityCutoffHz, at most 0.4 / dt_s.
double LoopVelocityCutoffHz(double dt_s);
/// The velocity axis's label: "y' [mm/s] (low-passed at 50 Hz)".
std::string LoopVelocityLabel(double dt_s);

/// f [kN] against y [mm] and against y' [mm/s] (LoopVelocity).
PageFigure Loops(const io::RunSignals& s, const RunReportOptions& o);

/// The spectra and G_yr, and the numbers the page quotes from them.
struct FrequencyFigures {
  std::optional<PageFigure> spectra, gyr;
  std::string summary_html;  ///< band, magnitude range, time lag ("" if none)
  std::vector<std::string> notes;
};
/// Welch spectra of r, y, e and the H1 estimate of G_yr over the excited band of r, with the notes
/// saying why one is missing.
FrequencyFigures Frequency(const io::RunSignals& s, const RunReportOptions& o);

/// The RTHS benchmark's criteria and their figure (scenarios with structure.reference_file).
struct BenchmarkSection {
  std::optional<PageFigure> figure;
  std::string table_html;  ///< the J1-J9 table ("" if none)
  std::string note;        ///< why there are no criteria ("" if there are)
};
/// The RTHS benchmark's J1-J9 table and figure (participants/benchmark_run.h), for a scenario with
/// structure.reference_file; empty otherwise, or a note if they cannot be computed.
BenchmarkSection Benchmark(const RunData& d, const RunReportOptions& o);

/// True if every panel has at least one finite point (io::Plot refuses a panel without one).
bool Drawable(const io::Figure& fig);

}  // namespace rths::report::run_figures
