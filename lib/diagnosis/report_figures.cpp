// The figures of the diagnosis report (diagnosis/report_figures.h).
#include "diagnosis/report_figures.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/localise.h"
#include "io/bode_figure.h"
#include "io/plot.h"
#include "signal/bode.h"
#include "signal/spectral.h"
#include "signal/spectrum_axes.h"

namespace rths::diagnosis {

namespace fs = std::filesystem;

namespace {

std::vector<double> Residual(const std::vector<double>& m, const std::vector<double>& p, std::size_t first) {
  std::vector<double> e;
  for (std::size_t k = first; k < m.size(); ++k) e.push_back(m[k] - p[k]);
  return e;
}

// Legend above the axes in one row (never over the data, and the plot keeps the figure's whole
// width), the same margins in every panel so stacked axes line up.
constexpr int kLeftMarginChars = 12;
constexpr int kRightMarginChars = 4;
void KeyAbove(io::Figure* fig) {
  fig->width_px = 1200;
  for (auto& p : fig->panels) {
    p.left_margin_chars = kLeftMarginChars;
    p.right_margin_chars = kRightMarginChars;
    if (p.key != "off") p.key = "outside top center horizontal";
  }
}

/// True if the verdict's prediction is the nominal one (no effect selected: `unknown`, `none`):
/// its curve would be drawn exactly over the nominal one and hide it, so it is left out.
bool SameAsNominal(const std::vector<double>& nominal, const std::vector<double>& final_prediction) {
  return nominal == final_prediction;
}

/// The nominal curve's legend: says it is also the verdict's when no effect was selected.
std::string NominalTitle(const std::string& base, bool same) {
  return same ? base + " (= the verdict's: no effect selected)" : base;
}

const std::string kMeasuredColor = "#0072B2", kNominalColor = "#D55E00", kFinalColor = "#009E73";

std::string ChannelQuantity(const std::string& ch) { return ch == "y" ? "Displacement y [mm]" : "Force f [kN]"; }

}  // namespace

std::pair<double, double> EnergyBand(const std::vector<double>& f_hz, const std::vector<double>& psd, double fraction) {
  if (f_hz.size() != psd.size() || f_hz.size() < 2) {
    throw Error("EnergyBand", fmt::format("{} frequencies for {} densities (need the same number, >= 2)", f_hz.size(),
                                          psd.size()));
  }
  if (!(fraction > 0.0 && fraction <= 1.0)) throw Error("EnergyBand", fmt::format("fraction {} (allowed: (0, 1])", fraction));
  double total = 0.0;
  for (std::size_t j = 1; j < psd.size(); ++j) total += std::isfinite(psd[j]) && psd[j] > 0 ? psd[j] : 0.0;
  if (!(total > 0.0)) throw Error("EnergyBand", "the spectrum holds no energy");
  const double lo_at = 0.5 * (1.0 - fraction) * total, hi_at = 0.5 * (1.0 + fraction) * total;
  double lo = f_hz[1], hi = f_hz.back(), sum = 0.0;
  bool lo_found = false;
  for (std::size_t j = 1; j < psd.size(); ++j) {
    sum += std::isfinite(psd[j]) && psd[j] > 0 ? psd[j] : 0.0;
    if (!lo_found && sum >= lo_at) {
      lo = f_hz[j];
      lo_found = true;
    }
    if (sum >= hi_at) {
      hi = f_hz[j];
      break;
    }
  }
  return {lo, hi};
}

io::Figure SpectrumFigure(const Traces::Record& t, const std::string& ch, std::size_t first) {
  const auto& m = ch == "y" ? t.y_meas : t.f_meas;
  const auto& pn = ch == "y" ? t.y_nom : t.f_nom;
  const auto& pf = ch == "y" ? t.y_fin : t.f_fin;
  std::vector<double> meas(m.begin() + static_cast<std::ptrdiff_t>(first), m.end());
  // 4 s segments (df = 0.25 Hz) where the record allows 8 of them: the axis starts at 0 Hz, as the
  // band table does, and the lowest band has points in it.
  const std::size_t L = std::max<std::size_t>(64, std::min<std::size_t>(static_cast<std::size_t>(std::lround(4.0 / t.dt_s)), meas.size() / 8));
  const auto sm = signal::WelchPsd(meas, t.dt_s, L);
  const auto sn = signal::WelchPsd(Residual(m, pn, first), t.dt_s, L);
  const auto sf = signal::WelchPsd(Residual(m, pf, first), t.dt_s, L);
  const bool same = SameAsNominal(pn, pf);
  std::vector<double> f_hz(sm.size());
  for (std::size_t j = 0; j < f_hz.size(); ++j) f_hz[j] = static_cast<double>(j) / (t.dt_s * static_cast<double>(L));
  const std::string unit = ch == "y" ? "mm^2/Hz" : "kN^2/Hz";
  io::Figure fig;
  fig.name = "spectrum_" + ch;
  const fs::path src(t.source);
  const std::string shown = src.filename() == "log.lcm" && !src.parent_path().filename().empty()
                                ? (src.parent_path().filename() / src.filename()).string()
                                : src.filename().string();
  auto p = io::MakePanel(fmt::format("channel {}: spectra (test record {})", ch, shown), "Frequency [Hz]",
                         fmt::format("PSD of {} [{}]", ch, unit));
  p.log_y = true;
  // 0 Hz to the band that carries the measured signal (1.5 x where it is within 60 dB of its peak),
  // eight decades under the highest density.
  const signal::SpectrumAxes ax = signal::SpectrumAxesOf(f_hz, sm, {&sm, &sn, &sf}, 60.0, 1.5, 8.0);
  p.x_range = std::make_pair(0.0, ax.f_hi_hz);
  if (ax.psd_hi > 0) p.y_range = std::make_pair(ax.psd_lo, ax.psd_hi);
  auto s1 = io::MakeSeries("measured", kMeasuredColor);
  auto s2 = io::MakeSeries(NominalTitle("residual, nominal model", same), kNominalColor);
  auto s3 = io::MakeSeries("residual, with the verdict's effects", kFinalColor);
  for (std::size_t j = 1; j < sm.size() && f_hz[j] <= ax.f_hi_hz; ++j) {
    const double f = f_hz[j];
    s1.x.push_back(f), s1.y.push_back(sm[j] > 0 ? sm[j] : NAN);
    s2.x.push_back(f), s2.y.push_back(sn[j] > 0 ? sn[j] : NAN);
    s3.x.push_back(f), s3.y.push_back(sf[j] > 0 ? sf[j] : NAN);
  }
  p.series = {s1, s2};
  if (!same) p.series.push_back(s3);
  fig.panels.push_back(p);
  KeyAbove(&fig);
  return fig;
}

namespace {

/// The FRF plot's frequency axis [Hz]: the input's kFrfEnergyFraction energy band (from 0 Hz
/// unless it starts well above) over its coherent points, else its strong ones; *mask: at least
/// two reliable points (coherence u -> y_meas at least kFrfMinCoherence) in it, so the others are left out.
std::pair<double, double> FrfAxis(const signal::CrossSpectra& sm, const signal::FrequencyResponseEstimate& hm, bool* mask) {
  double peak = 0.0;
  for (std::size_t j = 1; j < sm.s_uu.size(); ++j) peak = std::max(peak, sm.s_uu[j]);
  std::vector<double> strong(sm.s_uu.size(), 0.0), excited(sm.s_uu.size(), 0.0);
  bool coherent = false;
  for (std::size_t j = 1; j < sm.s_uu.size(); ++j) {
    if (sm.s_uu[j] < kFrfInputFloor * peak) continue;
    strong[j] = sm.s_uu[j];
    if (hm.coherence[j] >= kFrfMinCoherence) excited[j] = sm.s_uu[j], coherent = true;
  }
  auto [lo, hi] = peak > 0.0 ? EnergyBand(sm.f_hz, coherent ? excited : strong, kFrfEnergyFraction)
                             : std::make_pair(0.0, sm.f_hz.back());  // no input: the whole axis
  if (lo < 0.25 * hi) lo = 0.0;
  std::size_t reliable = 0;
  for (std::size_t j = 1; j < hm.f_hz.size(); ++j) {
    if (hm.f_hz[j] >= lo && hm.f_hz[j] <= hi && hm.coherence[j] >= kFrfMinCoherence) ++reliable;
  }
  *mask = reliable >= 2;
  return {lo, hi};
}

}  // namespace

io::Figure FrfFigure(const Traces::Record& t, std::size_t first) {
  std::vector<double> u(t.u.begin() + static_cast<std::ptrdiff_t>(first), t.u.end());
  std::vector<double> ym(t.y_meas.begin() + static_cast<std::ptrdiff_t>(first), t.y_meas.end());
  std::vector<double> yn(t.y_nom.begin() + static_cast<std::ptrdiff_t>(first), t.y_nom.end());
  std::vector<double> yf(t.y_fin.begin() + static_cast<std::ptrdiff_t>(first), t.y_fin.end());
  const std::size_t L = std::max<std::size_t>(64, std::min<std::size_t>(static_cast<std::size_t>(std::lround(2.0 / t.dt_s)), u.size() / 8));
  const auto sm = signal::WelchCrossSpectra(u, ym, t.dt_s, L);
  const auto hm = signal::H1FromSpectra(sm);
  const auto hn = signal::H1Estimate(u, yn, t.dt_s, L);
  const auto hf = signal::H1Estimate(u, yf, t.dt_s, L);
  bool mask = false;
  const std::pair<double, double> axis = FrfAxis(sm, hm, &mask);
  const double lo = axis.first, hi = axis.second;
  const bool same = SameAsNominal(t.y_nom, t.y_fin);
  // The responses over the axis, phase unwrapped from DC; where the measurement is not coherent
  // enough (if anywhere it is), magnitude and phase left out.
  const signal::FrequencyResponseEstimate* est[3] = {&hm, &hn, &hf};
  const char* titles[3] = {"measured", "nominal model", "with the verdict's effects"};
  const std::string colors[3] = {kMeasuredColor, kNominalColor, kFinalColor};
  std::vector<io::BodeTrace> traces(same ? 2 : 3);
  for (std::size_t i = 0; i < traces.size(); ++i) {
    const auto& e = *est[i];
    io::BodeTrace& tr = traces[i];
    tr.curve = signal::BodeBand(signal::BodeFromResponse(titles[i], e.f_hz, e.h, e.coherence), lo, hi);
    for (std::size_t k = 0; k < tr.curve.f_hz.size(); ++k) {
      if (mask && !(traces[0].curve.coherence[k] >= kFrfMinCoherence))  // the same grid
        tr.curve.magnitude[k] = tr.curve.phase_deg[k] = NAN;
    }
    tr.style = io::MakeSeries(i == 1 ? NominalTitle(titles[i], same) : titles[i], colors[i], static_cast<int>(i) + 1);
  }
  traces[0].style.width = 2.0;
  if (traces.size() > 2) traces[2].style.width = 2.5;  // on top of the measured curve it follows
  traces[0].coherence_style = io::MakeSeries("coherence", kMeasuredColor);
  auto threshold = io::MakeSeries(fmt::format("{:g}: the points below are left out", kFrfMinCoherence), "#666666", 2);
  threshold.x = {lo, hi};
  threshold.y = {kFrfMinCoherence, kFrfMinCoherence};
  io::BodeLayout layout;
  layout.f_range_hz = {lo, hi};
  layout.magnitude_label = "|G_yu| [mm/mm]";
  layout.lag_panel = false;
  layout.coherence_panel = true;
  layout.coherence_label = "Coherence u -> y_meas [-]";
  layout.coherence_extra = {threshold};
  layout.magnitude_key = layout.coherence_key = "top right";  // then above the panels (KeyAbove)
  layout.key_margin = false;
  io::Figure fig = io::BodeFigure(layout, traces);
  fig.name = "frf_y";
  fig.title = fmt::format("u -> y: measured vs model (H1, test record), over the input's {:g} % energy band {:.3g}-{:.3g} Hz; {}",
                          100 * kFrfEnergyFraction, lo, hi,
                          mask ? fmt::format("points with coherence < {:g} left out", kFrfMinCoherence)
                               : fmt::format("coherence < {:g} everywhere: nothing left out", kFrfMinCoherence));
  fig.panel_height_px = 260;
  KeyAbove(&fig);
  return fig;
}

io::Figure ConditionFigure(const Result& r) {
  io::Figure fig;
  fig.name = "conditions";
  for (const std::string ch : {"y", "f"}) {
    std::vector<std::string> names;
    bool starred = false;
    auto s1 = io::MakeSeries("share of the residual energy", kNominalColor);
    auto s2 = io::MakeSeries("share of the samples", kMeasuredColor);
    for (const auto& c : r.conditions) {
      if (c.channel != ch) continue;
      names.push_back(c.informative ? c.name : c.name + "*");
      starred = starred || !c.informative;
      s1.y.push_back(c.share_pct);
      s2.y.push_back(c.samples_pct);
    }
    if (names.empty()) continue;
    auto p = io::MakeBarPanel(fmt::format("channel {}: nominal residual by state condition (test records){}", ch,
                                          starred ? fmt::format("; * uninformative: holds in none or more than {:g} % "
                                                                "of the samples",
                                                                r.options.max_condition_samples_pct)
                                                  : ""),
                              "Share [%]", names, {s1, s2});
    p.xlabel = "State condition";
    double top = 0.0;
    for (double v : s1.y) top = std::max(top, v);
    for (double v : s2.y) top = std::max(top, v);
    p.y_range = std::make_pair(0.0, std::max(10.0, 1.1 * top));
    fig.panels.push_back(p);
  }
  KeyAbove(&fig);
  return fig;
}

io::Figure TraceFigure(const Traces::Record& t, const std::string& ch) {
  const auto& m = ch == "y" ? t.y_meas : t.f_meas;
  const auto& pn = ch == "y" ? t.y_nom : t.f_nom;
  const auto& pf = ch == "y" ? t.y_fin : t.f_fin;
  io::Figure fig;
  fig.name = "trace_" + ch;
  // The 2 s window with the largest nominal residual energy.
  const auto w = static_cast<std::size_t>(std::lround(2.0 / t.dt_s));
  std::size_t best = 0;
  double be = -1;
  for (std::size_t a = 0; a + w <= m.size(); a += w / 4) {
    double e = 0;
    for (std::size_t k = a; k < a + w; ++k) e += (m[k] - pn[k]) * (m[k] - pn[k]);
    if (e > be) be = e, best = a;
  }
  const std::size_t b = std::min(m.size(), best + w);
  const std::string unit = ch == "y" ? "mm" : "kN";
  auto p1 = io::MakePanel(fmt::format("channel {}: measured and predicted", ch), "Time [s]", ChannelQuantity(ch));
  auto p2 = io::MakePanel("residual: measured - predicted", "Time [s]", fmt::format("Residual {} [{}]", ch, unit));
  const bool same = SameAsNominal(pn, pf);
  auto s1 = io::MakeSeries("measured", kMeasuredColor), s2 = io::MakeSeries(NominalTitle("nominal", same), kNominalColor, 2),
       s3 = io::MakeSeries("with the verdict's effects", kFinalColor, 3);
  auto r1 = io::MakeSeries(NominalTitle("nominal", same), kNominalColor),
       r2 = io::MakeSeries("with the verdict's effects", kFinalColor);
  for (std::size_t k = best; k < b; ++k) {
    const double tt = static_cast<double>(k) * t.dt_s;
    s1.x.push_back(tt), s1.y.push_back(m[k]);
    s2.x.push_back(tt), s2.y.push_back(pn[k]);
    s3.x.push_back(tt), s3.y.push_back(pf[k]);
    r1.x.push_back(tt), r1.y.push_back(m[k] - pn[k]);
    r2.x.push_back(tt), r2.y.push_back(m[k] - pf[k]);
  }
  p1.series = same ? std::vector<io::Series>{s1, s2} : std::vector<io::Series>{s1, s2, s3};
  p2.series = same ? std::vector<io::Series>{r1} : std::vector<io::Series>{r1, r2};
  fig.panels = {p1, p2};
  fig.panel_height_px = 280;
  KeyAbove(&fig);
  return fig;
}

}  // namespace rths::diagnosis
