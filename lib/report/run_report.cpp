// A report for every run (docs/report.md): report.html and figures/*.png from a run folder.
#include "report/run_report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <optional>
#include <numeric>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"
#include "core/names.h"
#include "io/benchmark_run.h"
#include "io/plot.h"
#include "signal/benchmark_criteria.h"
#include "signal/spectral.h"

namespace rths::report {

namespace fs = std::filesystem;
using io::Figure;
using io::MakePanel;
using io::MakeSeries;
using io::Panel;
using io::Series;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;
// Colours of the signals, the same in every figure.
constexpr const char* kColorR = "black";
constexpr const char* kColorU = "#1f77b4";
constexpr const char* kColorY = "#d62728";
constexpr const char* kColorE = "#9467bd";
constexpr const char* kColorF = "#2ca02c";
constexpr const char* kColorI = "#ff7f0e";

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string(), "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool AllFinite(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
}

double PeakAbs(const std::vector<double>& x, std::size_t* at = nullptr) {
  double peak = 0.0;
  std::size_t where = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isfinite(x[i]) && std::abs(x[i]) > peak) {
      peak = std::abs(x[i]);
      where = i;
    }
  }
  if (at) *at = where;
  return peak;
}

double Rms(const std::vector<double>& x) {
  if (x.empty()) return 0.0;
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

bool AnyNonZero(const std::vector<double>& x) {
  return std::any_of(x.begin(), x.end(), [](double v) { return v != 0.0; });
}

/// A curve of y against x over the samples `idx`.
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

/// A time history of y against t, min/max-decimated to max_points.
Series History(const std::string& title, const std::string& color, const std::vector<double>& t,
               const std::vector<double>& y, std::size_t max_points) {
  return Curve(title, color, t, y, MinMaxDecimate(y, max_points));
}

/// Indices begin, begin + stride, ... < end with at most max_points of them.
std::vector<std::size_t> Strided(std::size_t begin, std::size_t end, std::size_t max_points) {
  std::vector<std::size_t> idx;
  if (end <= begin) return idx;
  const std::size_t stride = std::max<std::size_t>(1, (end - begin + max_points - 1) / max_points);
  for (std::size_t i = begin; i < end; i += stride) idx.push_back(i);
  return idx;
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

/// One figure of the page: the gnuplot figure, its heading and its caption (HTML).
struct PageFigure {
  Figure figure;
  std::string heading;
  std::string caption_html;
};

Figure NewFigure(const std::string& name, const RunReportOptions& o) {
  Figure f;
  f.name = name;
  f.gnuplot = o.gnuplot;
  f.width_px = 1100;
  f.panel_height_px = 300;
  return f;
}

// --- the figures ---------------------------------------------------------------------------

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
  Panel cur = MakePanel("Damper current", "t [s]", "current [A]");
  cur.series = {History("i_cmd (commanded)", kColorI, t, s.At("i_cmd_A").values, m),
                History("i_eff (effective)", kColorE, t, s.At("i_eff_A").values, m)};
  PageFigure pf{NewFigure("time_histories", o), "Time histories", ""};
  pf.figure.panels = {disp, force, cur};
  pf.caption_html =
      "Desired displacement r, actuator command u and measured displacement y [mm]; measured force f [kN]; "
      "commanded and effective damper current [A].";
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
  err.series = {History("e", kColorE, t, e, o.max_plot_points)};

  // r, u, y around the largest |e|: +-0.25 s (or the whole run if it is shorter).
  std::size_t at = 0;
  PeakAbs(e, &at);
  const std::size_t half = static_cast<std::size_t>(std::lround(0.25 / s.dt_s));
  const std::size_t lo = at > half ? at - half : 0;
  const std::size_t hi = std::min(t.size(), at + half + 1);
  const auto idx = Strided(lo, hi, o.max_plot_points);
  Panel zoom = MakePanel(fmt::format("Around the largest |e| ({:.4g} mm at t = {:.4f} s)", std::abs(e[at]), t[at]),
                         "t [s]", "displacement [mm]");
  zoom.series = {Curve("r (desired)", kColorR, t, s.At("r_mm").values, idx),
                 Curve("u (command)", kColorU, t, s.At("u_mm").values, idx),
                 Curve("y (measured)", kColorY, t, s.At("y_mm").values, idx)};
  PageFigure pf{NewFigure("tracking_error", o), "Tracking error", ""};
  pf.figure.panels = {err, zoom};
  pf.caption_html = "Top: e = r - y [mm] over the run. Bottom: r, u and y [mm] over the 0.5 s around the "
                    "largest |e|, every step.";
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

PageFigure Loops(const io::RunSignals& s, const RunReportOptions& o) {
  const auto& y = s.At("y_mm").values;
  const auto& f = s.At("f_kN").values;
  const std::vector<double> v = CentralDifference(y, s.dt_s);
  const auto idx = Strided(0, y.size(), o.max_loop_points);
  Panel fd = MakePanel("Force-displacement", "y [mm]", "f [kN]");
  fd.key = "off";
  fd.series = {Curve("f(y)", kColorF, y, f, idx)};
  Panel fv = MakePanel("Force-velocity", "y' [mm/s] (central difference)", "f [kN]");
  fv.key = "off";
  fv.series = {Curve("f(y')", kColorF, v, f, idx)};
  PageFigure pf{NewFigure("loops", o), "Force loops", ""};
  pf.figure.panels = {fd, fv};
  pf.figure.columns = 2;
  pf.figure.panel_height_px = 450;
  pf.caption_html = "Measured force f [kN] against the measured displacement y [mm] and against its velocity "
                    "y' = (y<sub>k+1</sub> - y<sub>k-1</sub>) / (2 dt) [mm/s].";
  if (idx.size() < y.size())
    pf.caption_html += fmt::format(" Every {}th step drawn.", y.size() / std::max<std::size_t>(1, idx.size()));
  return pf;
}

/// Welch segment length: a power of two of steps near welch_segment_s, at most n/4, at least 32.
std::size_t SegmentLength(std::size_t n, double dt_s, double segment_s) {
  const double want = std::max(32.0, segment_s / dt_s);
  std::size_t l = 32;
  while (l * 2 <= n / 4 && static_cast<double>(l * 2) <= want * std::sqrt(2.0)) l *= 2;
  return l;
}

/// The spectra and G_yr, and the numbers the page quotes from them.
struct FrequencyFigures {
  std::optional<PageFigure> spectra, gyr;
  std::string summary_html;  ///< band, magnitude range, time lag ("" if none)
  std::vector<std::string> notes;
};

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
  const auto positive = [](double v) { return v > 0.0 ? v : kNaN; };

  // Spectra, log-log, DC left out.
  Panel psd = MakePanel("", "frequency [Hz]", "PSD [mm^2/Hz]");
  psd.log_x = psd.log_y = true;
  Series sr = MakeSeries("r", kColorR), sy = MakeSeries("y", kColorY), se = MakeSeries("e = r - y", kColorE);
  for (std::size_t i = 1; i < cs.f_hz.size(); ++i) {
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
  sp.figure.panels = {psd};
  sp.figure.panel_height_px = 450;
  sp.caption_html = fmt::format("Welch power spectral densities of r, y and e [mm<sup>2</sup>/Hz]: every step, "
                                "segments of {} steps ({:.3g} s, df = {:.3g} Hz), {} segments, Hann window, 50 % "
                                "overlap.",
                                l, static_cast<double>(l) * s.dt_s, cs.df_hz, cs.segments);
  out.spectra = sp;

  // The excited band of r: where S_rr is within band_db of its peak (DC left out).
  double peak = 0.0;
  for (std::size_t i = 1; i < cs.s_uu.size(); ++i) peak = std::max(peak, cs.s_uu[i]);
  if (!(peak > 0.0)) {
    out.notes.push_back("no G_yr: r does not move (its spectrum is zero)");
    return out;
  }
  const double floor = peak * std::pow(10.0, -o.band_db / 10.0);
  std::size_t i_lo = 0, i_hi = 0;
  for (std::size_t i = 1; i < cs.s_uu.size(); ++i) {
    if (cs.s_uu[i] >= floor) {
      if (i_lo == 0) i_lo = i;
      i_hi = i;
    }
  }
  const std::span<const std::complex<double>> band_h(h1.h.data() + i_lo, i_hi - i_lo + 1);
  const std::vector<double> phase = signal::UnwrapPhase(band_h);
  Panel mag = MakePanel("", "frequency [Hz]", "|G_yr| [-]");
  Panel ph = MakePanel("", "frequency [Hz]", "phase [deg]");
  Panel coh = MakePanel("", "frequency [Hz]", "coherence [-]");
  mag.key = ph.key = "off";
  coh.key = "bottom left";
  Series sm = MakeSeries("|G_yr|", kColorY), sph = MakeSeries("phase", kColorY);
  Series sc = MakeSeries("gamma^2", kColorU), sth = MakeSeries(fmt::format("mask below {:g}", o.min_coherence), "black", 2);
  std::vector<double> lag_ms, mags;
  std::size_t kept = 0;
  for (std::size_t i = i_lo; i <= i_hi; ++i) {
    const double f = h1.f_hz[i];
    const bool ok = h1.coherence[i] >= o.min_coherence && cs.s_uu[i] >= floor;
    const double m = std::abs(h1.h[i]);
    const double p_deg = phase[i - i_lo] * 180.0 / kPi;
    sm.x.push_back(f);
    sm.y.push_back(ok ? m : kNaN);
    sph.x.push_back(f);
    sph.y.push_back(ok ? p_deg : kNaN);
    sc.x.push_back(f);
    sc.y.push_back(h1.coherence[i]);
    if (ok) {
      ++kept;
      mags.push_back(m);
      lag_ms.push_back(-phase[i - i_lo] / (2.0 * kPi * f) * 1e3);
    }
  }
  const double f_lo = h1.f_hz[i_lo], f_hi = h1.f_hz[i_hi];
  sth.x = {f_lo, f_hi};
  sth.y = {o.min_coherence, o.min_coherence};
  sth.width = 1.0;
  const std::pair<double, double> xr{f_lo, f_hi > f_lo ? f_hi : f_lo + cs.df_hz};
  mag.x_range = ph.x_range = coh.x_range = xr;
  coh.y_range = std::make_pair(0.0, 1.05);
  mag.series = {sm};
  ph.series = {sph};
  coh.series = {sc, sth};
  if (kept == 0) {
    out.notes.push_back(fmt::format("no G_yr: no frequency of the excited band {:.3g}-{:.3g} Hz has a coherence "
                                    ">= {:g}",
                                    f_lo, f_hi, o.min_coherence));
    return out;
  }
  PageFigure g{NewFigure("gyr", o), "G_yr = Y / R", ""};
  g.figure.panels = {mag, ph, coh};
  g.figure.panel_height_px = 260;
  g.caption_html = fmt::format(
      "H1 estimate of the tracking transfer function G<sub>yr</sub> = S<sub>ry</sub> / S<sub>rr</sub> (same "
      "segments as the spectra): magnitude [-], unwrapped phase [deg] and coherence &gamma;<sup>2</sup> [-] over the "
      "excited band of r ({:.3g}-{:.3g} Hz: its PSD within {:g} dB of its peak). Points with &gamma;<sup>2</sup> &lt; "
      "{:g} are masked ({} of {} kept). A perfect tracker has |G<sub>yr</sub>| = 1 and phase 0.",
      f_lo, f_hi, o.band_db, o.min_coherence, kept, i_hi - i_lo + 1);
  out.gyr = g;
  std::vector<double> sorted = lag_ms;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  out.summary_html = fmt::format(
      "<tr><th>G<sub>yr</sub> over {:.3g}-{:.3g} Hz</th><td>|G<sub>yr</sub>| {:.4g} to {:.4g}; equivalent time lag "
      "-phase/(2&pi;f) median {:.3g} ms</td></tr>\n",
      f_lo, f_hi, *std::min_element(mags.begin(), mags.end()), *std::max_element(mags.begin(), mags.end()),
      sorted[sorted.size() / 2]);
  return out;
}

/// The RTHS benchmark's criteria and their figure (scenarios with structure.reference_file).
struct BenchmarkSection {
  std::optional<PageFigure> figure;
  std::string table_html;  ///< the J1-J9 table ("" if none)
  std::string note;        ///< why there are no criteria ("" if there are)
};

BenchmarkSection Benchmark(const RunData& d, const RunReportOptions& o) {
  BenchmarkSection out;
  if (!d.scenario || d.scenario->structure.reference_file.empty()) return out;
  signal::BenchmarkSignals b;
  signal::BenchmarkCriteria c;
  try {
    b = io::BenchmarkSignalsFromRun(d.signals, *d.scenario);
    c = signal::BenchmarkCriteriaFrom(b);
  } catch (const std::exception& e) {
    out.note = std::string("no benchmark criteria J1-J9: ") + e.what();
    return out;
  }
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
  out.table_html = h;

  const std::vector<double>& t = d.signals.At("t_s").values;
  const std::size_t m = o.max_plot_points;
  const std::size_t ai = static_cast<std::size_t>(a - 1);
  Panel act = MakePanel(fmt::format("Actuator floor {}", a), "t [s]", "displacement [mm]");
  Series sxr = History(fmt::format("x_r,{} (reference)", a), "black", t, b.x_r[ai], m);
  sxr.dash = 2;
  act.series = {History("x_t = r (target)", kColorU, t, b.x_t, m), History("x_m = y (measured)", kColorY, t, b.x_m, m),
                sxr};
  std::vector<double> e_t(b.x_m.size()), e_r(b.x_m.size());
  for (std::size_t k = 0; k < e_t.size(); ++k) {
    e_t[k] = b.x_m[k] - b.x_t[k];
    e_r[k] = b.x_m[k] - b.x_r[ai][k];
  }
  Panel err = MakePanel("Errors of the measured displacement", "t [s]", "error [mm]");
  err.series = {History("x_m - x_t (J2, J3)", kColorE, t, e_t, m),
                History(fmt::format("x_m - x_r,{} (J4, J5)", a), kColorF, t, e_r, m)};
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
  }
  pf.caption_html = fmt::format(
      "Top: the target x<sub>t</sub> = r, the measured x<sub>m</sub> = y and the reference structure's floor {0} "
      "x<sub>r,{0}</sub> [mm]; then the errors x<sub>m</sub> - x<sub>t</sub> and x<sub>m</sub> - x<sub>r,{0}</sub> "
      "[mm]; then each other floor of the numerical substructure x<sub>n,i</sub> against the reference "
      "x<sub>r,i</sub> [mm] (J6-J9){1}.",
      a, c.floors.size() > floors.size() ? fmt::format(", {} of {} floors shown", floors.size(), c.floors.size()) : "");
  out.figure = pf;
  return out;
}

// --- the page ------------------------------------------------------------------------------

std::string Row(const std::string& name, const std::string& value_html, const std::string& id = "") {
  return fmt::format("<tr><th>{}</th><td{}>{}</td></tr>\n", name, id.empty() ? "" : " id=\"" + id + "\"", value_html);
}

/// A number from summary.json, or nullopt.
std::optional<double> JsonNumber(const nlohmann::json& j, const char* key) {
  if (j.is_object() && j.contains(key) && j[key].is_number()) return j[key].get<double>();
  return std::nullopt;
}

std::string JsonText(const nlohmann::json& j, const char* key, const std::string& fallback = "") {
  if (j.is_object() && j.contains(key) && j[key].is_string()) return j[key].get<std::string>();
  return fallback;
}

std::string ScenarioTable(const RunData& d) {
  std::string h;
  h += Row("scenario file", HtmlEscape(JsonText(d.summary, "scenario", (d.run_dir / "scenario.toml").string())));
  if (!d.scenario) {
    h += Row("settings", d.scenario_toml.empty() ? "no scenario.toml in the run folder"
                                                 : "scenario.toml does not load here: " + HtmlEscape(d.scenario_error));
    return h;
  }
  const scenario::Scenario& s = *d.scenario;
  h += Row("name", HtmlEscape(s.run.name));
  h += Row("step, duration",
           fmt::format("dt = {:g} s ({:g} Hz), {:g} s, {} steps", s.run.dt_s, 1.0 / s.run.dt_s, s.run.duration_s, s.steps()));
  const auto& c = s.controller;
  std::string ctrl(NameOf(control::kControllerKindNames, c.kind));
  if (c.kind == control::ControllerKind::kFf || c.kind == control::ControllerKind::kFfLp ||
      c.kind == control::ControllerKind::kFfLqg)
    ctrl += ", design model " + c.model.name;
  if (c.kind == control::ControllerKind::kFfLp || c.kind == control::ControllerKind::kBumplessLp)
    ctrl += fmt::format(", low-pass {:g} Hz order {}", c.lp_cutoff_hz, c.lp_order);
  if (c.kind == control::ControllerKind::kPoly3 || c.kind == control::ControllerKind::kLead)
    ctrl += fmt::format(", delay {:g} ms", c.delay_ms);
  h += Row("controller", HtmlEscape(ctrl));
  const auto& p = s.plant;
  std::string plant(NameOf(models::kPlantKindNames, p.kind));
  if (p.kind == models::PlantKind::kLinear) plant += ", actuator " + p.actuator.name;
  if (p.kind == models::PlantKind::kBenchmark) {  // the specimen is inside Gp: the experimental substructure
    const auto& b = p.benchmark.params;
    plant += fmt::format(", experimental substructure m_e {:g} kg, k_e {:g} N/m, zeta_e {:g}{}", b.m_e_kg, b.k_e_N_per_m,
                         b.zeta_e, p.benchmark.daq.enabled ? ", DAQ on" : "");
  } else {
    plant += ", specimen " + std::string(NameOf(models::kSpecimenNames, p.specimen));
  }
  if (p.RigMode()) plant += ", rig mode (effects on)";
  if (p.noise_y_mm_rms > 0 || p.noise_f_kN_rms > 0)
    plant += fmt::format(", sensor noise {:g} mm / {:g} kN RMS", p.noise_y_mm_rms, p.noise_f_kN_rms);
  h += Row("plant", HtmlEscape(plant));
  const auto& st = s.structure;
  std::string structure(NameOf(models::kStructureModeNames, st.mode));
  const signal::SignalSpec* exc = &st.ground;
  std::string exc_unit = "mm/s^2";
  if (st.mode == models::StructureMode::kPredefined) {
    structure += " (r from a history)";
    exc = &st.desired;
    exc_unit = "mm";
  } else if (st.kind == models::StructureKind::kSdof) {
    structure += fmt::format(", SDOF {:g} kg, {:g} Hz, {:g} % damping, {:g} specimen(s)", st.mass_kg,
                             st.frequency_hz, 100.0 * st.damping_ratio, st.specimen_count);
  } else {
    structure += fmt::format(", file {} (specimen at DOF {}), {:g} specimen(s)", st.file, st.actuator_dof,
                             st.specimen_count);
  }
  h += Row("structure", HtmlEscape(structure));
  std::string excitation = (st.mode == models::StructureMode::kPredefined ? "desired displacement: "
                                                                           : "ground acceleration: ") +
                           std::string(NameOf(signal::kSignalKindNames, exc->kind));
  if (exc->kind == signal::SignalKind::kBlwn)
    excitation += fmt::format(", 0-{:g} Hz, RMS {:g} {}, seed {}", exc->band_hz, exc->rms, exc_unit, exc->seed);
  else if (exc->kind == signal::SignalKind::kFile)
    excitation += fmt::format(", {} x {:g}", exc->file, exc->scale);
  h += Row("excitation", HtmlEscape(excitation));
  const auto& sa = s.semiactive;
  h += Row("damper current",
           HtmlEscape(fmt::format("{}, max {:g} A", NameOf(control::kSemiactiveModeNames, sa.mode), sa.max_current_A)));
  h += Row("real time", s.realtime.enabled ? "paced to the wall clock ([realtime] enabled)" : "not paced");
  return h;
}

std::string Pct(double v) { return fmt::format("{:.4g} %", v); }

std::string MetricsTable(const RunData& d) {
  const nlohmann::json& j = d.summary;
  const auto& sig = d.signals;
  const std::int64_t steps = static_cast<std::int64_t>(sig.steps());
  std::string h;
  if (j.is_object()) {
    const int code = j.value("exit_code", -1);
    std::string status = HtmlEscape(JsonText(j, "status", "?")) + fmt::format(" (exit code {})", code);
    const std::string stopped = JsonText(j, "stopped", "no");
    if (stopped != "no") status += ": " + HtmlEscape(stopped);
    h += Row("status", status, "status");
  } else {
    h += Row("status", d.log_complete ? "unknown (no summary.json); the log is complete"
                                      : "unknown (no summary.json); the log is truncated");
  }
  h += Row("steps", fmt::format("{} of {} ({:.4g} s of {:.4g} s)", steps, d.steps_planned,
                                static_cast<double>(steps) * sig.dt_s, static_cast<double>(d.steps_planned) * sig.dt_s),
           "steps");
  // Eq. 31 and the peaks: summary.json's (what `rths run` printed), else the log's.
  const double nrmse = JsonNumber(j, "tracking_nrmse_pct").value_or(d.metrics.tracking_nrmse_pct);
  const double peak_f = JsonNumber(j, "peak_force_kN").value_or(d.metrics.peak_force_kN);
  const double peak_y = JsonNumber(j, "peak_displacement_mm").value_or(d.metrics.peak_displacement_mm);
  h += Row("tracking error (RMS, Eq. 31)", Pct(nrmse), "tracking_nrmse_pct");
  h += Row("peak |f|", fmt::format("{:.4g} kN", peak_f), "peak_force_kN");
  h += Row("peak |y|", fmt::format("{:.4g} mm", peak_y), "peak_displacement_mm");
  if (steps > 0) {
    std::size_t at = 0;
    const double pe = PeakAbs(sig.At("e_mm").values, &at);
    h += Row("peak |r|", fmt::format("{:.4g} mm", PeakAbs(sig.At("r_mm").values)));
    h += Row("tracking error e = r - y", fmt::format("RMS {:.4g} mm, peak |e| {:.4g} mm at t = {:.4f} s",
                                                     Rms(sig.At("e_mm").values), pe, sig.At("t_s").values[at]));
    h += Row("peak |i_eff|", fmt::format("{:.4g} A", PeakAbs(sig.At("i_eff_A").values)));
  }
  h += Row("Eq. 20 acceleration extrapolation error",
           Pct(JsonNumber(j, "accel_extrapolation_rms_err_pct").value_or(d.metrics.accel_extrapolation_rms_err_pct)));
  h += Row("Eq. 21 velocity prediction error",
           Pct(JsonNumber(j, "velocity_prediction_rms_err_pct").value_or(d.metrics.velocity_prediction_rms_err_pct)));
  if (!j.is_object()) return h;
  if (const auto rate = JsonNumber(j, "steps_per_s"); rate && *rate > 0)
    h += Row("rate", fmt::format("{:.0f} steps/s ({:.3g}x real time), {} transport, {:.3g} s wall", *rate,
                                 *rate * sig.dt_s, HtmlEscape(JsonText(j, "transport", "?")),
                                 JsonNumber(j, "wall_s").value_or(0.0)));
  if (j.contains("link") && j["link"].is_object()) {
    const auto& l = j["link"];
    h += Row("link", fmt::format("{} re-requests, {} messages repaired, {} duplicates ignored; {} duplicates logged",
                                 l.value("rerequests", 0), l.value("repaired", 0), l.value("duplicates_ignored", 0),
                                 j.value("duplicates_logged", 0)));
  }
  if (j.contains("failure") && j["failure"].is_object()) {
    const auto& f = j["failure"];
    h += Row("failure", HtmlEscape(fmt::format("{} at step {}: {} (exit code {})", f.value("participant", "?"),
                                               f.value("step", -1), f.value("what", ""), f.value("exit_code", 0))));
  }
  if (j.contains("participants") && j["participants"].is_object()) {
    std::string ps;
    for (const auto& [role, p] : j["participants"].items()) {
      if (!ps.empty()) ps += ", ";
      ps += fmt::format("{} {}", role, p.is_object() ? p.value("exit_code", -1) : -1);
    }
    h += Row("participants (exit codes)", HtmlEscape(ps));
  }
  return h;
}

std::string RealtimeTable(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains("realtime") || !j["realtime"].is_object()) return "";
  const auto& rt = j["realtime"];
  if (!rt.contains("steps")) return "";
  const double period_us = rt.value("period_us", 0.0);
  std::string h = "<h2 id=\"realtime\">Real time</h2>\n<table>\n";
  h += Row("paced at", fmt::format("{:.0f} Hz (dt {:g} ms)", period_us > 0 ? 1e6 / period_us : 0.0, period_us / 1e3));
  const int processes = rt.value("processes", 0);
  std::string setup = fmt::format("SCHED_FIFO {} in {} of {} process(es), memory locked in {} of {}",
                                  rt.value("priority", 0), rt.value("sched_fifo_processes", 0), processes,
                                  rt.value("memory_locked_processes", 0), processes);
  if (const std::string notes = rt.value("setup_notes", std::string()); !notes.empty())
    setup += "; NOT real-time: " + notes;
  h += Row("set-up", HtmlEscape(setup));
  h += Row("step latency (request to barrier)",
           fmt::format("p50 {:.0f} us, p99 {:.0f} us, p99.9 {:.0f} us, max {:.0f} us", rt.value("latency_p50_us", 0.0),
                       rt.value("latency_p99_us", 0.0), rt.value("latency_p999_us", 0.0),
                       rt.value("latency_max_us", 0.0)),
           "latency");
  h += Row("deadline misses",
           fmt::format("{} of {} steps ({:.4f} %), longest run {}, first at step {}",
                       rt.value("deadline_misses", std::int64_t{0}), rt.value("steps", std::int64_t{0}),
                       100.0 * rt.value("miss_fraction", 0.0), rt.value("max_consecutive_misses", std::int64_t{0}),
                       rt.value("first_miss_step", std::int64_t{-1})),
           "deadline_misses");
  h += Row("latest release", fmt::format("{:.0f} us after its deadline", rt.value("max_release_late_us", 0.0)));
  return h + "</table>\n";
}

/// The banner lines: why the page is not the report of a clean, finished run.
std::vector<std::string> Warnings(const RunData& d, bool* failed) {
  std::vector<std::string> w;
  const auto steps = static_cast<std::int64_t>(d.signals.steps());
  const bool has_summary = d.summary.is_object();
  const std::string status = has_summary ? JsonText(d.summary, "status", "?") : "";
  const int code = has_summary ? d.summary.value("exit_code", -1) : 0;
  const bool bad_status = has_summary && (status != "completed" || code != 0);
  *failed = !d.log_complete || bad_status || !d.abort_reason.empty();
  if (*failed) {
    // One headline: how it ended (summary.json), why (summary.json's `stopped`, else the log's ABORT).
    std::string why = has_summary ? JsonText(d.summary, "stopped", "no") : "no";
    if (why == "no") why = d.abort_reason;
    std::string line = "This run did not finish";
    if (bad_status) line += fmt::format(": {} (exit code {})", status, code);
    line += why.empty() ? (d.log_complete ? "" : " (log.lcm: " + d.truncation_reason + ")") : ": " + why;
    w.push_back(line + ".");
    w.push_back(fmt::format("Its log holds {} complete step(s) of {} planned ({:.4g} s of {:.4g} s): everything "
                            "below covers those steps.",
                            steps, d.steps_planned, static_cast<double>(steps) * d.signals.dt_s,
                            static_cast<double>(d.steps_planned) * d.signals.dt_s));
    if (!why.empty() && !d.log_complete) w.push_back("log.lcm: " + d.truncation_reason);
  }
  if (!has_summary) {
    w.push_back(d.summary_error + ": how the run ended (status, exit code), link and real-time figures are unknown; "
                "the numbers below come from the log");
  }
  if (!d.scenario_error.empty()) w.push_back("scenario.toml does not load here: " + d.scenario_error);
  if (d.scenario_toml.empty()) w.push_back("no scenario.toml in the run folder");
  for (const auto& n : d.notes) w.push_back(n);
  return w;
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

void WriteFileAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!(f << text) || !(f.flush())) throw Error(tmp.string(), "cannot write");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw Error(path.string(), "cannot write: " + ec.message());
}

constexpr const char* kStyle = R"(
body { font-family: sans-serif; max-width: 1150px; margin: 1.5em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.25em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
.where { color: #666; margin-top: 0; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { text-align: left; vertical-align: top; padding: 0.25em 0.8em 0.25em 0; border-bottom: 1px solid #eee; }
th { font-weight: 600; white-space: nowrap; }
.banner { padding: 0.8em 1em; margin: 1em 0; border-radius: 4px; font-size: 1.05em; }
.banner.failed { background: #fde2e1; border: 2px solid #c62828; }
.banner.note { background: #fff4d6; border: 1px solid #d9a400; }
.banner.ok { background: #e5f4e7; border: 1px solid #2e7d32; }
.banner p { margin: 0.3em 0; }
figure { margin: 1em 0 2em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #444; font-size: 0.95em; margin-top: 0.3em; }
pre { background: #f6f6f6; padding: 0.8em; overflow-x: auto; font-size: 0.9em; }
)";

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::vector<double> CentralDifference(const std::vector<double>& x, double dt_s) {
  const std::size_t n = x.size();
  std::vector<double> v(n, 0.0);
  if (n < 2) return v;
  v[0] = (x[1] - x[0]) / dt_s;
  v[n - 1] = (x[n - 1] - x[n - 2]) / dt_s;
  for (std::size_t k = 1; k + 1 < n; ++k) v[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt_s);
  return v;
}

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
      const std::string ran = JsonText(d.summary, "scenario");
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
    if (const auto st = JsonNumber(d.summary, "steps"); st && static_cast<std::int64_t>(*st) != d.metrics.steps)
      d.notes.push_back(fmt::format("summary.json says {} steps but the log holds {} complete steps (the log was "
                                    "changed after the run?)",
                                    static_cast<std::int64_t>(*st), d.metrics.steps));
    const std::string sha = JsonText(d.summary, "scenario_sha256");
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
  files.warnings = Warnings(d, &failed);

  // The figures.
  std::vector<PageFigure> figures;
  std::vector<std::string> figure_notes;
  std::string frequency_summary;
  std::string benchmark_html;  // the J1-J9 table (scenarios with structure.reference_file)
  if (d.signals.steps() >= 2) {
    figures.push_back(TimeHistories(d.signals, o));
    figures.push_back(TrackingError(d.signals, o));
    figures.push_back(Loops(d.signals, o));
    if (auto ad = Adaptation(d.signals, o)) figures.push_back(*ad);
    FrequencyFigures ff = Frequency(d.signals, o);
    if (ff.spectra) figures.push_back(*ff.spectra);
    if (ff.gyr) figures.push_back(*ff.gyr);
    frequency_summary = ff.summary_html;
    figure_notes = ff.notes;
    BenchmarkSection bs = Benchmark(d, o);
    if (bs.figure) figures.push_back(*bs.figure);
    benchmark_html = bs.table_html;
    if (!bs.note.empty()) figure_notes.push_back(bs.note);
  } else {
    figure_notes.push_back(fmt::format("no figures: the log holds {} complete step(s)", d.signals.steps()));
  }
  std::vector<PageFigure> drawn;
  for (auto& pf : figures) {
    if (Drawable(pf.figure)) {
      drawn.push_back(std::move(pf));
    } else {
      figure_notes.push_back(fmt::format("no figure {}: a panel has no finite value (the run diverged?)", pf.figure.name));
    }
  }
  // An earlier report's figure that this one does not draw would stay beside the page: remove it.
  for (const char* stale : {"time_histories", "tracking_error", "loops", "adaptation", "spectra", "gyr", "benchmark"}) {
    if (std::any_of(drawn.begin(), drawn.end(), [&](const PageFigure& pf) { return pf.figure.name == stale; }))
      continue;
    for (const char* ext : {".png", ".dat", ".gp"}) fs::remove(fig_dir / (std::string(stale) + ext), ec);
  }
  // One gnuplot process per figure, all at once (each writes its own files).
  std::vector<std::future<io::PlotFiles>> jobs;
  for (const auto& pf : drawn) jobs.push_back(std::async(std::launch::async, [&pf, &fig_dir] { return io::Plot(pf.figure, fig_dir); }));
  for (auto& j : jobs) files.figures.push_back(j.get().png);

  // The page.
  const std::string name = d.scenario ? d.scenario->run.name : d.run_dir.filename().string();
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>rths run report: " +
                  HtmlEscape(name) + "</title>\n<style>" + kStyle + "</style></head><body>\n";
  h += "<h1>Run report: " + HtmlEscape(name) + "</h1>\n";
  h += "<p class=\"where\">" + HtmlEscape(fs::absolute(d.run_dir).lexically_normal().string()) +
       " &mdash; written by <code>rths report</code> from log.lcm, summary.json and scenario.toml</p>\n";
  if (files.warnings.empty()) {
    h += "<div class=\"banner ok\" id=\"banner\"><p>The run completed: " + std::to_string(files.steps) + " of " +
         std::to_string(files.steps_planned) + " steps.</p></div>\n";
  } else {
    h += std::string("<div class=\"banner ") + (failed ? "failed" : "note") + "\" id=\"banner\">\n";
    for (std::size_t i = 0; i < files.warnings.size(); ++i) {
      const std::string line = HtmlEscape(files.warnings[i]);
      h += failed && i == 0 ? "<p><strong>" + line + "</strong></p>\n" : "<p>" + line + "</p>\n";
    }
    h += "</div>\n";
  }
  h += "<h2 id=\"results\">Results</h2>\n<table>\n" + MetricsTable(d) + frequency_summary + "</table>\n";
  if (!benchmark_html.empty()) h += "<h2 id=\"criteria\">Benchmark criteria J1-J9</h2>\n" + benchmark_html;
  h += RealtimeTable(d.summary);
  h += "<h2 id=\"scenario\">Scenario</h2>\n<table>\n" + ScenarioTable(d) + "</table>\n";
  if (!d.scenario_toml.empty()) {
    h += "<details><summary>scenario.toml (SHA-256 " + scenario::Sha256Hex(d.scenario_toml) + ")</summary>\n<pre>" +
         HtmlEscape(d.scenario_toml) + "</pre></details>\n";
  }
  h += "<h2 id=\"figures\">Figures</h2>\n";
  if (!figure_notes.empty()) {
    h += "<div class=\"banner note\">\n";
    for (const auto& n : figure_notes) h += "<p>" + HtmlEscape(n) + "</p>\n";
    h += "</div>\n";
  }
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    const std::string png = files.figures[i].filename().string();
    h += fmt::format("<h3 id=\"{}\">{}</h3>\n<figure><img src=\"figures/{}\" alt=\"{}\" width=\"{}\">\n"
                     "<figcaption>{} (<a href=\"figures/{}\">{}</a>; data and gnuplot script beside it)</figcaption>"
                     "</figure>\n",
                     drawn[i].figure.name, HtmlEscape(drawn[i].heading), png, HtmlEscape(drawn[i].heading),
                     drawn[i].figure.width_px, drawn[i].caption_html, png, png);
  }
  h += "<p class=\"where\">Units: mm, mm/s, kN, A, s. Eq. 31: RMS of r - y over the RMS of r, in %. Method: "
       "docs/report.md.</p>\n</body></html>\n";
  for (const auto& n : figure_notes) files.warnings.push_back(n);
  WriteFileAtomically(files.html, h);
  return files;
}

ReportFiles WriteRunReport(const fs::path& run_dir, const RunReportOptions& options) {
  CheckOptions(options);
  return WriteRunReport(LoadRunData(run_dir), options);
}

}  // namespace rths::report
