// The run report's figures (report/run_figures.h).
#include "report/run_figures.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <span>

#include <fmt/format.h>

#include "diagnosis/channel_models.h"
#include "io/bode_figure.h"
#include "participants/benchmark_run.h"
#include "report/html.h"
#include "signal/spectrum_axes.h"
#include "signal/benchmark_criteria.h"
#include "signal/bode.h"
#include "signal/derivative.h"
#include "signal/metrics.h"
#include "signal/spectral.h"

namespace rths::report {

using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Panel;
using io::Series;

namespace run_figures {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Half the window of the tracking error's zoom [s].
constexpr double kZoomHalfS = 0.125;
/// A coherence within this of 1 over the whole band is a flat line at 1 on the page (a run without
/// sensor noise: our simulations reach 0.9997 at worst): not drawn.
constexpr double kFlatCoherence = 1e-3;
/// Space between a curve's peaks and the frame, as a fraction of the plot's height.
constexpr double kPeakMargin = 0.06;
/// A legend above the axes, in a row: it covers no curve (inside, it hid the peaks).
constexpr const char* kKeyAbove = "outside top center horizontal";
// Colours of the signals, the same in every figure.
constexpr const char* kColorR = "black";
constexpr const char* kColorU = "#1f77b4";
constexpr const char* kColorY = "#d62728";
constexpr const char* kColorE = "#9467bd";
constexpr const char* kColorF = "#2ca02c";
constexpr const char* kColorI = "#ff7f0e";

bool AllFinite(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
}

/// True if every value equals the first (an empty series too).
bool Constant(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [&](double v) { return v == x.front(); });
}

bool AnyNonZero(const std::vector<double>& x) {
  return std::any_of(x.begin(), x.end(), [](double v) { return v != 0.0; });
}

Figure NewFigure(const std::string& name, const RunReportOptions& o) { return PageFrame(name, o.gnuplot); }

}  // namespace

Series Curve(const std::string& title, const std::string& color, const std::vector<double>& x,
             const std::vector<double>& y, const std::vector<std::size_t>& idx) {
  Series s = MakeSeries(title, color);
  s.width = 1.2;
  s.x.reserve(idx.size());
  s.y.reserve(idx.size());
  for (std::size_t i : idx) {
    s.x.push_back(x[i]);
    s.y.push_back(y[i]);
  }
  return s;
}

Series History(const std::string& title, const std::string& color, const std::vector<double>& t,
               const std::vector<double>& y, std::size_t max_points) {
  return Curve(title, color, t, y, MinMaxDecimate(y, max_points));
}

Figure PageFrame(const std::string& name, const std::string& gnuplot) {
  Figure f;
  f.name = name;
  f.gnuplot = gnuplot;
  f.width_px = 1100;
  f.panel_height_px = 300;
  return f;
}

std::vector<std::size_t> Strided(std::size_t begin, std::size_t end, std::size_t max_points) {
  std::vector<std::size_t> idx;
  if (end <= begin) return idx;
  const std::size_t stride = std::max<std::size_t>(1, (end - begin + max_points - 1) / max_points);
  for (std::size_t i = begin; i < end; i += stride) idx.push_back(i);
  return idx;
}

std::size_t SegmentLength(std::size_t n, double dt_s, double segment_s) {
  const double want = std::max(32.0, segment_s / dt_s);
  std::size_t l = 32;
  while (l * 2 <= n / 4 && static_cast<double>(l * 2) <= want * std::sqrt(2.0)) l *= 2;
  return l;
}

PageFigure TimeHistories(const io::RunSignals& s, const RunReportOptions& o) {
  const auto& t = s.At("t_s").values;
  const std::size_t m = o.max_plot_points;
  Panel disp = MakePanel("Displacements", "t [s]", "displacement [mm]");
  disp.series = {History("r (desired)", kColorR, t, s.At("r_mm").values, m),
                 History("u (command)", kColorU, t, s.At("u_mm").values, m),
                 History("y (measured)", kColorY, t, s.At("y_mm").values, m)};
  Panel force = MakePanel("Specimen force", "t [s]", "force [kN]");
  force.series = {History("f (measured)", kColorF, t, s.At("f_kN").values, m)};
  if (AnyNonZero(s.At("f_desired_kN").values)) {
    Series fd = History("f desired (clipped-optimal, one damper)", "black", t, s.At("f_desired_kN").values, m);
    fd.dash = 2;
    fd.width = 1.0;
    force.series.push_back(fd);
  }
  // Peaks off the frame, and the legends above the axes where they cover no curve.
  for (Panel* p : {&disp, &force}) {
    p->y_margin_fraction = kPeakMargin;
    p->key = kKeyAbove;
  }
  PageFigure pf{NewFigure("time_histories", o), "Time histories", ""};
  pf.figure.panels = {disp, force};
  pf.caption_html = "Desired displacement r, actuator command u and measured displacement y [mm]; measured force f [kN]";
  // A current that never changes is a line of text, not a third of the figure.
  const auto& i_cmd = s.At("i_cmd_A").values;
  const auto& i_eff = s.At("i_eff_A").values;
  if (Constant(i_cmd) && Constant(i_eff)) {
    pf.caption_html += fmt::format(". The damper current is constant over the run: commanded {:.4g} A, effective "
                                   "{:.4g} A (not drawn).",
                                   i_cmd.empty() ? 0.0 : i_cmd[0], i_eff.empty() ? 0.0 : i_eff[0]);
  } else {
    Panel cur = MakePanel("Damper current", "t [s]", "current [A]");
    cur.series = {History("i_cmd (commanded)", kColorI, t, i_cmd, m), History("i_eff (effective)", kColorE, t, i_eff, m)};
    cur.y_margin_fraction = kPeakMargin;
    cur.key = kKeyAbove;
    pf.figure.panels.push_back(cur);
    pf.caption_html += "; commanded and effective damper current [A].";
  }
  pf.caption_html += " The command u lies under y at this scale: the tracking error's figure shows them apart.";
  if (t.size() > m)
    pf.caption_html += fmt::format(" Each curve shows the minimum and maximum of {} windows of {:.3g} s "
                                   "(every peak kept); the spectra below use every step.",
                                   m / 2, static_cast<double>(t.size()) * s.dt_s / static_cast<double>(m / 2));
  return pf;
}

PageFigure TrackingError(const io::RunSignals& s, const RunReportOptions& o) {
  const auto& t = s.At("t_s").values;
  const auto& e = s.At("e_mm").values;
  Panel err = MakePanel("Tracking error e = r - y", "t [s]", "e [mm]");
  err.key = "off";
  err.y_margin_fraction = kPeakMargin;
  err.series = {History("e", kColorE, t, e, o.max_plot_points)};

  // r, u, y around the largest |e|: +-kZoomHalfS (or the whole run if it is shorter), where the
  // command's lead over the response is a visible fraction of the window.
  std::size_t at = 0;
  signal::PeakAbs(e, &at);
  const std::size_t half = static_cast<std::size_t>(std::lround(kZoomHalfS / s.dt_s));
  const std::size_t lo = at > half ? at - half : 0;
  const std::size_t hi = std::min(t.size(), at + half + 1);
  const auto idx = Strided(lo, hi, o.max_plot_points);
  Panel zoom = MakePanel(fmt::format("Around the largest |e| ({:.4g} mm at t = {:.4f} s)", std::abs(e[at]), t[at]),
                         "t [s]", "displacement [mm]");
  zoom.series = {Curve("r (desired)", kColorR, t, s.At("r_mm").values, idx),
                 Curve("u (command)", kColorU, t, s.At("u_mm").values, idx),
                 Curve("y (measured)", kColorY, t, s.At("y_mm").values, idx)};
  zoom.x_range = std::make_pair(t[lo], t[hi - 1]);
  zoom.y_margin_fraction = kPeakMargin;
  zoom.key = kKeyAbove;
  PageFigure pf{NewFigure("tracking_error", o), "Tracking error", ""};
  pf.figure.panels = {err, zoom};
  pf.figure.panel_height_px = 360;
  pf.caption_html = fmt::format("Top: e = r - y [mm] over the run, on its own axis. Bottom: r, u and y [mm] over the "
                                "{:.3g} s around the largest |e|, every step: the command u leads the response y by "
                                "about the actuator's lag.",
                                2 * kZoomHalfS);
  return pf;
}

/// An adaptive controller's coefficients over the run (columns a0, a1_s, ... of RunSignals), one
/// panel each (they differ by orders of magnitude); nullopt for a fixed controller.
std::optional<PageFigure> Adaptation(const io::RunSignals& s, const RunReportOptions& o) {
  if (s.Find("a0") == nullptr) return std::nullopt;
  const auto& t = s.At("t_s").values;
  PageFigure pf{NewFigure("adaptation", o), "Adaptive controller: coefficients", ""};
  pf.figure.panel_height_px = 200;
  const char* colors[4] = {kColorU, kColorY, kColorR, kColorF};
  const char* names[4] = {"a0", "a1_s", "a2_s2", "a3_s3"};
  for (int i = 0; i < 4; ++i) {
    const io::SignalColumn* c = s.Find(names[i]);
    if (c == nullptr) break;
    Panel p = MakePanel("", "t [s]", c->unit.empty() ? "a0 [-]" : fmt::format("a{} [{}]", i, c->unit));
    p.key = "off";
    p.series = {History(names[i], colors[i], t, c->values, o.max_plot_points)};
    pf.figure.panels.push_back(p);
  }
  pf.caption_html = "The coefficients of u = a0 x_t + a1 x_t' + a2 x_t'' (+ a3 x_t''') the controller used at "
                    "each step (command_t.adapt; ats and ambc, docs/controllers.md): a0 is about the inverse "
                    "of the plant's gain, a1 about its delay [s].";
  return pf;
}

std::optional<PageFigure> RealtimeLatency(const RunData& d, const RunReportOptions& o) {
  if (!d.summary.is_object() || !d.summary.contains("realtime")) return std::nullopt;
  const nlohmann::json& rt = d.summary["realtime"];
  if (!rt.is_object() || !rt.value("paced", false) || !rt.contains("latency_windows")) return std::nullopt;
  const nlohmann::json& w = rt["latency_windows"];
  const auto steps = w.value("window_steps", std::int64_t{0});
  if (steps <= 0 || !w.contains("max_us") || w["max_us"].empty()) return std::nullopt;
  const double window_s = static_cast<double>(steps) * d.signals.dt_s;
  Series lat = MakeSeries("largest step latency per window", kColorU);
  Series missed = MakeSeries("windows with deadline misses", kColorY);
  missed.with = "points pt 7 ps 1.2";
  std::int64_t windows_missed = 0;
  for (std::size_t i = 0; i < w["max_us"].size(); ++i) {
    const double t = (static_cast<double>(i) + 0.5) * window_s;
    const double ms = w["max_us"][i].get<double>() / 1e3;
    lat.x.push_back(t);
    lat.y.push_back(ms);
    if (i < w["misses"].size() && w["misses"][i].get<std::int64_t>() > 0) {
      missed.x.push_back(t);
      missed.y.push_back(ms);
      ++windows_missed;
    }
  }
  Series deadline = MakeSeries("deadline dt", "black", 2);
  deadline.x = {0.0, static_cast<double>(lat.x.size()) * window_s};
  deadline.y = {1e3 * d.signals.dt_s, 1e3 * d.signals.dt_s};
  deadline.width = 1.0;
  Panel p = MakePanel("", "t [s]", "latency [ms]");
  p.log_y = true;
  p.series = {lat, deadline};
  if (!missed.x.empty()) p.series.push_back(missed);
  PageFigure pf{NewFigure("realtime", o), "Real time: step latency over the run", ""};
  pf.figure.panels = {p};
  pf.caption_html = fmt::format(
      "The largest step latency (release to the barrier complete, as the clock measured it) in each window of {} "
      "steps ({:.3g} s) [ms], log scale, against the deadline dt; {} window(s) held deadline misses{}.",
      steps, window_s, windows_missed, windows_missed > 0 ? " (marked)" : "");
  return pf;
}

double LoopVelocityCutoffHz(double dt_s) { return std::min(kLoopVelocityCutoffHz, 0.4 / dt_s); }

std::vector<double> LoopVelocity(const std::vector<double>& y_mm, double dt_s) {
  if (y_mm.size() < 4 || !AllFinite(y_mm)) return signal::Derivative(y_mm, dt_s);
  return diagnosis::SmoothMotion(y_mm, dt_s, LoopVelocityCutoffHz(dt_s)).v_mm_s;
}

std::string LoopVelocityLabel(double dt_s) {
  return fmt::format("y' [mm/s] (low-passed at {:g} Hz)", LoopVelocityCutoffHz(dt_s));
}

PageFigure Loops(const io::RunSignals& s, const RunReportOptions& o) {
  const auto& y = s.At("y_mm").values;
  const auto& f = s.At("f_kN").values;
  const std::vector<double> v = LoopVelocity(y, s.dt_s);
  const auto idx = Strided(0, y.size(), o.max_loop_points);
  Panel fd = MakePanel("Force-displacement", "y [mm]", "f [kN]");
  fd.key = "off";
  fd.series = {Curve("f(y)", kColorF, y, f, idx)};
  Panel fv = MakePanel("Force-velocity", LoopVelocityLabel(s.dt_s), "f [kN]");
  fv.key = "off";
  fv.series = {Curve("f(y')", kColorF, v, f, idx)};
  fd.margin_fraction = fv.margin_fraction = kPeakMargin;  // the loop's extremes off the frame
  PageFigure pf{NewFigure("loops", o), "Force loops", ""};
  pf.figure.panels = {fd, fv};
  pf.figure.columns = 2;
  pf.figure.panel_height_px = 450;
  pf.caption_html = fmt::format("Measured force f [kN] against the measured displacement y [mm] and against its "
                                "velocity y' [mm/s]: y low-passed at {:g} Hz (zero phase) and differentiated, so that "
                                "sensor noise on y does not hide the loop.",
                                LoopVelocityCutoffHz(s.dt_s));
  if (idx.size() < y.size())
    pf.caption_html += fmt::format(" Every {}th step drawn.", y.size() / std::max<std::size_t>(1, idx.size()));
  return pf;
}

namespace {

/// The Welch PSDs of r, y and e [mm^2/Hz], log-log, DC left out.
PageFigure SpectraFigure(const signal::CrossSpectra& cs, const std::vector<double>& s_ee, std::size_t l, double dt_s,
                         const RunReportOptions& o) {
  const auto positive = [](double v) { return v > 0.0 ? v : kNaN; };
  Panel psd = MakePanel("", "frequency [Hz]", "PSD [mm^2/Hz]");
  psd.log_y = true;
  // The band that carries r and eight decades under the highest density: not every bin to
  // Nyquist and down to round-off (a simulation's e reaches 1e-20).
  const signal::SpectrumAxes ax = signal::SpectrumAxesOf(cs.f_hz, cs.s_uu, {&cs.s_uu, &cs.s_yy, &s_ee}, 40.0, 1.5, 8.0);
  psd.x_range = std::make_pair(0.0, ax.f_hi_hz);
  if (ax.psd_hi > 0) psd.y_range = std::make_pair(ax.psd_lo, ax.psd_hi);
  Series sr = MakeSeries("r", kColorR), sy = MakeSeries("y", kColorY), se = MakeSeries("e = r - y", kColorE);
  for (std::size_t i = 1; i < cs.f_hz.size() && cs.f_hz[i] <= ax.f_hi_hz; ++i) {
    sr.x.push_back(cs.f_hz[i]);
    sr.y.push_back(positive(cs.s_uu[i]));
    sy.x.push_back(cs.f_hz[i]);
    sy.y.push_back(positive(cs.s_yy[i]));
    se.x.push_back(cs.f_hz[i]);
    se.y.push_back(positive(s_ee[i]));
  }
  sy.dash = 2;
  psd.series = {sr, sy, se};
  PageFigure sp{NewFigure("spectra", o), "Spectra", ""};
  sp.figure.title = "Power spectral densities of r (desired), y (measured) and e = r - y (Welch)";
  sp.figure.panels = {psd};
  sp.figure.panel_height_px = 450;
  sp.caption_html = fmt::format("Welch power spectral densities of r, y and e [mm<sup>2</sup>/Hz]: every step, "
                                "segments of {} steps ({:.3g} s, df = {:.3g} Hz), {} segments, Hann window, 50 % "
                                "overlap. Drawn over the band that carries r, 0-{:.3g} Hz (1.5 times the highest "
                                "frequency at which its PSD is within 40 dB of its peak), down to eight decades "
                                "below the highest density.",
                                l, static_cast<double>(l) * dt_s, cs.df_hz, cs.segments, ax.f_hi_hz);
  return sp;
}

/// The excited band of r: the first and last bins (DC left out) whose S_rr is within band_db of
/// its peak, and that floor; nullopt if r does not move.
struct ExcitedBand {
  std::size_t i_lo = 0, i_hi = 0;
  double floor = 0.0;  ///< [mm^2/Hz]
};
std::optional<ExcitedBand> FindExcitedBand(const signal::CrossSpectra& cs, double band_db) {
  double peak = 0.0;
  for (std::size_t i = 1; i < cs.s_uu.size(); ++i) peak = std::max(peak, cs.s_uu[i]);
  if (!(peak > 0.0)) return std::nullopt;
  ExcitedBand b;
  b.floor = peak * std::pow(10.0, -band_db / 10.0);
  for (std::size_t i = 1; i < cs.s_uu.size(); ++i) {
    if (cs.s_uu[i] >= b.floor) {
      if (b.i_lo == 0) b.i_lo = i;
      b.i_hi = i;
    }
  }
  return b;
}

/// G_yr's figure (magnitude, phase, coherence over the band, low-coherence points masked) and its
/// row of the results table; a note instead if no point of the band is coherent enough.
void GyrFigure(const signal::CrossSpectra& cs, const signal::FrequencyResponseEstimate& h1, const ExcitedBand& band,
               const RunReportOptions& o, FrequencyFigures* out) {
  const std::size_t i_lo = band.i_lo, i_hi = band.i_hi;
  const std::size_t n = i_hi - i_lo + 1;
  const signal::BodeCurve gyr = signal::BodeFromResponse("G_yr", std::span<const double>(h1.f_hz).subspan(i_lo, n),
                                                         std::span<const std::complex<double>>(h1.h).subspan(i_lo, n),
                                                         std::span<const double>(h1.coherence).subspan(i_lo, n));
  // Masked: the points with a low coherence, or below the band's floor, left out of magnitude and
  // phase (their coherence is drawn).
  io::BodeTrace trace;
  trace.curve = gyr;
  trace.style = MakeSeries("|G_yr|", kColorY);
  trace.phase_title = "phase";
  trace.coherence_style = MakeSeries("gamma^2", kColorU);
  std::vector<double> lag_ms, mags;
  std::size_t kept = 0;
  for (std::size_t i = i_lo; i <= i_hi; ++i) {
    const bool ok = h1.coherence[i] >= o.min_coherence && cs.s_uu[i] >= band.floor;
    if (ok) {
      ++kept;
      mags.push_back(gyr.magnitude[i - i_lo]);
      lag_ms.push_back(gyr.lag_ms[i - i_lo]);
    } else {
      trace.curve.magnitude[i - i_lo] = trace.curve.phase_deg[i - i_lo] = kNaN;
    }
  }
  const double f_lo = h1.f_hz[i_lo], f_hi = h1.f_hz[i_hi];
  if (kept == 0) {
    out->notes.push_back(fmt::format("no G_yr: no frequency of the excited band {:.3g}-{:.3g} Hz has a coherence "
                                     ">= {:g}",
                                     f_lo, f_hi, o.min_coherence));
    return;
  }
  Series sth = MakeSeries(fmt::format("mask below {:g}", o.min_coherence), "black", 2);
  sth.x = {f_lo, f_hi};
  sth.y = {o.min_coherence, o.min_coherence};
  sth.width = 1.0;
  // A simulation without sensor noise is a deterministic map from r to y: its coherence is 1 but
  // for the damper's slight nonlinearity, and a panel of it would be a flat line. It is drawn when
  // it says something.
  double min_coherence = 1.0;
  for (std::size_t i = i_lo; i <= i_hi; ++i) min_coherence = std::min(min_coherence, h1.coherence[i]);
  const bool coherence_flat = min_coherence > 1.0 - kFlatCoherence;
  io::BodeLayout layout;
  layout.f_range_hz = {f_lo, f_hi > f_lo ? f_hi : f_lo + cs.df_hz};
  layout.x_label = "frequency [Hz]";
  layout.magnitude_title = "Magnitude";
  layout.magnitude_label = "|G_yr| [-]";
  layout.phase_title = "Phase (unwrapped)";
  layout.phase_label = "phase [deg]";
  layout.lag_panel = false;
  layout.coherence_panel = !coherence_flat;
  layout.coherence_title = "Coherence";
  layout.coherence_label = "coherence [-]";
  layout.coherence_extra = {sth};
  layout.magnitude_key = "off";
  layout.coherence_key = "bottom left";
  layout.key_margin = false;
  PageFigure g{NewFigure("gyr", o), "G_yr = Y / R", ""};
  g.figure.title = "G_yr = Y / R: measured displacement y over desired displacement r (H1 estimate)";
  g.figure.panels = io::BodeFigure(layout, {trace}).panels;
  g.figure.panel_height_px = 280;
  g.caption_html = fmt::format(
      "H1 estimate of the tracking transfer function G<sub>yr</sub> = S<sub>ry</sub> / S<sub>rr</sub> (same "
      "segments as the spectra): magnitude [-], unwrapped phase [deg] and coherence &gamma;<sup>2</sup> [-] over the "
      "excited band of r ({:.3g}-{:.3g} Hz: its PSD within {:g} dB of its peak). Points with &gamma;<sup>2</sup> &lt; "
      "{:g} are masked ({} of {} kept). A perfect tracker has |G<sub>yr</sub>| = 1 and phase 0.{}",
      f_lo, f_hi, o.band_db, o.min_coherence, kept, i_hi - i_lo + 1,
      coherence_flat ? fmt::format(" The coherence is not drawn: it is 1 to within {:g} over the whole band (its "
                                   "least is {:.5f}), as in a run without sensor noise.",
                                   kFlatCoherence, min_coherence)
                     : std::string());
  out->gyr = g;
  std::vector<double> sorted = lag_ms;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  out->summary_html = fmt::format(
      "<tr><th>G<sub>yr</sub> over {:.3g}-{:.3g} Hz</th><td>|G<sub>yr</sub>| {:.4g} to {:.4g}; equivalent time lag "
      "-phase/(2&pi;f) median {:.3g} ms</td></tr>\n",
      f_lo, f_hi, *std::min_element(mags.begin(), mags.end()), *std::max_element(mags.begin(), mags.end()),
      sorted[sorted.size() / 2]);
}

}  // namespace

FrequencyFigures Frequency(const io::RunSignals& s, const RunReportOptions& o) {
  FrequencyFigures out;
  const auto& r = s.At("r_mm").values;
  const auto& y = s.At("y_mm").values;
  const auto& e = s.At("e_mm").values;
  const std::size_t n = r.size();
  if (n < 128) {
    out.notes.push_back(fmt::format("no spectra or G_yr: {} steps are too few (at least 128)", n));
    return out;
  }
  if (!AllFinite(r) || !AllFinite(y)) {
    out.notes.push_back("no spectra or G_yr: r or y is not finite everywhere (the run diverged)");
    return out;
  }
  const std::size_t l = SegmentLength(n, s.dt_s, o.welch_segment_s);
  const signal::CrossSpectra cs = signal::WelchCrossSpectra(r, y, s.dt_s, l);
  const std::vector<double> s_ee = signal::WelchPsd(e, s.dt_s, l);
  const auto h1 = signal::H1FromSpectra(cs);
  out.spectra = SpectraFigure(cs, s_ee, l, s.dt_s, o);
  const std::optional<ExcitedBand> band = FindExcitedBand(cs, o.band_db);
  if (!band) {
    out.notes.push_back("no G_yr: r does not move (its spectrum is zero)");
    return out;
  }
  GyrFigure(cs, h1, *band, o, &out);
  return out;
}

namespace {

/// The J1-J9 table (HTML) and the line saying what it was computed from.
std::string BenchmarkTable(const RunData& d, const signal::BenchmarkSignals& b, const signal::BenchmarkCriteria& c) {
  const signal::BenchmarkCriteria r = c.Rounded();
  const int a = b.actuator_floor;
  auto pct = [](double v) { return std::isfinite(v) ? fmt::format("{:.2f} %", v) : std::string("n/a"); };
  std::string h = "<table id=\"benchmark_criteria\">\n<tr><th>criterion</th><th>value</th><th>what</th></tr>\n";
  auto row = [&](const std::string& name, const std::string& value, const std::string& what) {
    std::string id = name;
    std::replace(id.begin(), id.end(), ' ', '_');
    h += fmt::format("<tr><th>{}</th><td id=\"{}\">{}</td><td>{}</td></tr>\n", name, id, value, what);
  };
  row("J1", std::isfinite(r.J1_ms) ? fmt::format("{:.1f} ms", r.J1_ms) : "n/a",
      fmt::format("time delay of x<sub>m</sub> behind x<sub>t</sub>: the lag in 0-49 steps of largest correlation "
                  "({} steps)",
                  c.lag_samples));
  row("J2", pct(r.J2_pct), "std(x<sub>m</sub> - x<sub>t</sub>) / std(x<sub>t</sub>): tracking error");
  row("J3", pct(r.J3_pct), "max|x<sub>m</sub> - x<sub>t</sub>| / max|x<sub>t</sub>|: peak tracking error");
  row("J4", pct(r.J4_pct), fmt::format("std(x<sub>m</sub> - x<sub>r,{0}</sub>) / std(x<sub>r,{0}</sub>): against the "
                                       "reference structure",
                                       a));
  row("J5", pct(r.J5_pct), fmt::format("max|x<sub>m</sub> - x<sub>r,{0}</sub>| / max|x<sub>r,{0}</sub>|", a));
  // J6, J7: std ratios of the first two other floors; J8, J9: their max ratios (in that order).
  const std::size_t named = std::min<std::size_t>(2, r.floors.size());
  const double std_values[2] = {r.J6_pct, r.J7_pct}, max_values[2] = {r.J8_pct, r.J9_pct};
  for (std::size_t i = 0; i < named; ++i)
    row(i == 0 ? "J6" : "J7", pct(std_values[i]),
        fmt::format("std(x<sub>n,{0}</sub> - x<sub>r,{0}</sub>) / std(x<sub>r,{0}</sub>): floor {0}", r.floors[i].floor));
  for (std::size_t i = 0; i < named; ++i)
    row(i == 0 ? "J8" : "J9", pct(max_values[i]),
        fmt::format("max|x<sub>n,{0}</sub> - x<sub>r,{0}</sub>| / max|x<sub>r,{0}</sub>|: floor {0}", r.floors[i].floor));
  for (std::size_t i = named; i < r.floors.size(); ++i)
    row(fmt::format("floor {}", r.floors[i].floor), fmt::format("{} / {}", pct(r.floors[i].std_pct), pct(r.floors[i].max_pct)),
        "std / max ratios as J6 / J8, for this floor");
  h += "</table>\n<p class=\"where\">RTHS benchmark (Silva et al. 2020; docs/benchmark.md), over the " +
       std::to_string(b.x_m.size()) + " logged steps: x<sub>m</sub> = y (measured), x<sub>t</sub> = r (the numerical "
       "substructure's floor " + std::to_string(a) + "), x<sub>n,i</sub> its floors, x<sub>r,i</sub> the reference "
       "structure (" + HtmlEscape(d.scenario->structure.reference_file) +
       ") integrated offline under the logged ground acceleration. J1 to 0.1 ms, the others to 0.01 %.</p>\n";
  return h;

}

/// The actuator floor (target, measured, reference), its errors, and the other floors against the
/// reference (at most 6 panels: the lowest 5 and the top).
PageFigure BenchmarkFigure(const RunData& d, const signal::BenchmarkSignals& b, const signal::BenchmarkCriteria& c,
                           const RunReportOptions& o) {
  const int a = b.actuator_floor;
  const std::vector<double>& t = d.signals.At("t_s").values;
  const std::size_t m = o.max_plot_points;
  const std::size_t ai = static_cast<std::size_t>(a - 1);
  Panel act = MakePanel(fmt::format("Actuator floor {}", a), "t [s]", "displacement [mm]");
  Series sxr = History(fmt::format("x_r,{} (reference)", a), "black", t, b.x_r[ai], m);
  sxr.dash = 2;
  // The target last and dashed, over the measured and the reference it lies under (they differ by
  // a few per cent): drawn first, it was hidden though the legend listed it.
  Series sxt = History("x_t = r (target)", kColorU, t, b.x_t, m);
  sxt.dash = 3;
  act.series = {History("x_m = y (measured)", kColorY, t, b.x_m, m), sxr, sxt};
  std::vector<double> e_t(b.x_m.size()), e_r(b.x_m.size());
  for (std::size_t k = 0; k < e_t.size(); ++k) {
    e_t[k] = b.x_m[k] - b.x_t[k];
    e_r[k] = b.x_m[k] - b.x_r[ai][k];
  }
  // The two errors overlap in time: the one of larger RMS is drawn first, beneath, so that the
  // smaller stays on top and visible (x_m - x_r,a is usually the larger: J4 > J2).
  Panel err =
      MakePanel("Errors of the measured displacement (the smaller drawn over the larger)", "t [s]", "error [mm]");
  Series s_et = History("x_m - x_t (J2, J3)", kColorE, t, e_t, m);
  Series s_er = History(fmt::format("x_m - x_r,{} (J4, J5)", a), kColorF, t, e_r, m);
  const bool target_larger = signal::Rms(e_t) > signal::Rms(e_r);
  err.series = target_larger ? std::vector<Series>{s_et, s_er} : std::vector<Series>{s_er, s_et};
  PageFigure pf{NewFigure("benchmark", o), "Benchmark: measured, target and reference", ""};
  pf.figure.panels = {act, err};
  // The other floors: numerical against reference (J6-J9), at most 6 panels (the lowest 5 and the top).
  std::vector<int> floors;
  for (const auto& f : c.floors) floors.push_back(f.floor);
  if (floors.size() > 6) floors.erase(floors.begin() + 5, floors.end() - 1);
  for (int f : floors) {
    const std::size_t fi = static_cast<std::size_t>(f - 1);
    Panel p = MakePanel(fmt::format("Floor {}", f), "t [s]", "displacement [mm]");
    Series r_i = History(fmt::format("x_r,{} (reference)", f), "black", t, b.x_r[fi], m);
    r_i.dash = 2;
    p.series = {History(fmt::format("x_n,{} (numerical)", f), kColorU, t, b.x_n[fi], m), r_i};
    pf.figure.panels.push_back(p);
  }
  pf.figure.panel_height_px = 260;
  // Legends beside the axes (the curves fill the panels), equal margins so the time axes line up.
  std::vector<const Panel*> panels;
  for (const Panel& p : pf.figure.panels) panels.push_back(&p);
  const int right = io::KeyMarginChars(panels);
  pf.figure.width_px = 1200;
  for (Panel& p : pf.figure.panels) {
    p.key = "outside right top";
    p.left_margin_chars = 10;
    p.right_margin_chars = right;
    p.y_margin_fraction = kPeakMargin;  // peaks off the frame
  }
  pf.caption_html = fmt::format(
      "Top: the target x<sub>t</sub> = r, the measured x<sub>m</sub> = y and the reference structure's floor {0} "
      "x<sub>r,{0}</sub> [mm]; then the errors x<sub>m</sub> - x<sub>t</sub> and x<sub>m</sub> - x<sub>r,{0}</sub> "
      "[mm]; then each other floor of the numerical substructure x<sub>n,i</sub> against the reference "
      "x<sub>r,i</sub> [mm] (J6-J9){1}.",
      a, c.floors.size() > floors.size() ? fmt::format(", {} of {} floors shown", floors.size(), c.floors.size()) : "");
  return pf;
}

}  // namespace

BenchmarkSection Benchmark(const RunData& d, const RunReportOptions& o) {
  BenchmarkSection out;
  if (!d.scenario || d.scenario->structure.reference_file.empty()) return out;
  signal::BenchmarkSignals b;
  signal::BenchmarkCriteria c;
  try {
    b = participants::BenchmarkSignalsFromRun(d.signals, *d.scenario);
    c = signal::BenchmarkCriteriaFrom(b);
  } catch (const std::exception& e) {
    out.note = std::string("no benchmark criteria J1-J9: ") + e.what();
    return out;
  }
  out.table_html = BenchmarkTable(d, b, c);
  out.figure = BenchmarkFigure(d, b, c, o);
  return out;
}

/// True if every panel has at least one finite point (io::Plot refuses a panel without one).
bool Drawable(const Figure& fig) {
  for (const Panel& p : fig.panels) {
    bool any = false;
    for (const Series& s : p.series)
      for (std::size_t i = 0; i < s.x.size() && !any; ++i) any = std::isfinite(s.x[i]) && std::isfinite(s.y[i]);
    if (!any) return false;
  }
  return true;
}

}  // namespace run_figures

std::vector<std::size_t> MinMaxDecimate(const std::vector<double>& x, std::size_t max_points) {
  const std::size_t n = x.size();
  std::vector<std::size_t> idx;
  if (n <= max_points || max_points < 4) {
    idx.resize(n);
    std::iota(idx.begin(), idx.end(), std::size_t{0});
    return idx;
  }
  const std::size_t buckets = max_points / 2;
  idx.reserve(2 * buckets);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    std::size_t i_min = lo, i_max = lo;
    for (std::size_t i = lo; i < hi; ++i) {
      // NaN never wins a comparison: a bucket of NaN keeps its first sample (the line breaks there).
      if (x[i] < x[i_min]) i_min = i;
      if (x[i] > x[i_max]) i_max = i;
    }
    idx.push_back(std::min(i_min, i_max));
    if (i_max != i_min) idx.push_back(std::max(i_min, i_max));
  }
  return idx;
}

}  // namespace rths::report
