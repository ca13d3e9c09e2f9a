#include "ident/actuator_fit.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include <fmt/format.h>

namespace rths::ident {

signal::BodeCurve BodeFromModel(const std::string& name, const PoleModel& model, const std::vector<double>& f_hz,
                                double zoh_dt_s) {
  std::vector<std::complex<double>> h;
  if (zoh_dt_s > 0.0) {
    const ZohModel d = Discretise(model, zoh_dt_s);
    for (double f : f_hz) h.push_back(ZohResponse(d, f));
  } else {
    for (double f : f_hz) h.push_back(model.Response(f));
  }
  return signal::BodeFromResponse(name, f_hz, h);
}

ActuatorFit FitActuator(std::span<const double> u_mm, std::span<const double> y_mm, double dt_s,
                        const IdentifyOptions& options) {
  ActuatorFit a;
  IdentifyOptions o = options;
  o.fit.zoh_dt_s = 0.0;
  a.continuous = Identify(u_mm, y_mm, dt_s, o);
  o.fit.zoh_dt_s = dt_s;
  a.zoh = Identify(u_mm, y_mm, dt_s, o);
  return a;
}

std::string ActuatorFit::Report() const {
  return continuous.Report() +
         fmt::format("\nZOH-consistent fit (the continuous model whose zero-order-hold discretisation at dt = {} s "
                     "matches the measured response):\n{}",
                     zoh.dt_s, zoh.fit.Report()) +
         fmt::format("time domain: Eq. 31 error of the predicted y {:.3f} %\n", zoh.prediction.model_error_pct);
}

std::string ActuatorFit::ModelToml(const std::string& title) const { return ScenarioFragment(continuous, zoh, title); }

namespace {

/// The measured H1 on (0, fmax_hz] at the points whose input was excited (S_uu at least
/// min_excitation of its peak there, |H1| > 0), phase unwrapped over them.
signal::BodeCurve MeasuredCurve(const IdentifyResult& r, double fmax_hz) {
  double peak = 0.0;
  for (std::size_t i = 0; i < r.s_uu.size(); ++i)
    if (r.frf.f_hz[i] <= fmax_hz) peak = std::max(peak, r.s_uu[i]);
  std::vector<double> f, coherence;
  std::vector<std::complex<double>> h;
  for (std::size_t i = 1; i < r.frf.f_hz.size() && r.frf.f_hz[i] <= fmax_hz; ++i) {
    if (r.s_uu[i] < r.options.min_excitation * peak || std::abs(r.frf.h[i]) == 0.0) continue;
    f.push_back(r.frf.f_hz[i]);
    h.push_back(r.frf.h[i]);
    coherence.push_back(r.frf.coherence[i]);
  }
  return signal::BodeFromResponse("measured H1", f, h, coherence);
}

/// `style` with x = the curve's frequencies and y = `column`.
io::Series Drawn(io::Series style, const signal::BodeCurve& c, const std::vector<double>& column) {
  style.x = c.f_hz;
  style.y = column;
  return style;
}

}  // namespace

io::Figure ActuatorFit::Bode(const std::string& title) const {
  using io::MakePanel;
  using io::MakeSeries;
  using io::Series;
  const double fmax = std::min(50.0, 0.5 / continuous.dt_s);
  std::vector<double> grid;
  for (int i = 1; i <= 500; ++i) grid.push_back(fmax * i / 500.0);
  const auto m = MeasuredCurve(continuous, fmax);
  const auto c = BodeFromModel("Eq. 15 fit", continuous.fit.model, grid, 0.0);
  const auto z = BodeFromModel("ZOH-consistent fit", zoh.fit.model, grid, zoh.dt_s);
  Series m_style = MakeSeries(m.name, io::ReadableColors()[0]);
  m_style.width = 2.0;
  Series c_style = MakeSeries(c.name, "#000000", 2);
  c_style.width = 2.0;
  Series z_style = MakeSeries(z.name, io::ReadableColors()[1], 3);
  z_style.width = 3.5;
  // The models' time-lag range [ms], for the lag axis (the measured lag scatters at low f).
  double lag_lo = 1e300, lag_hi = -1e300;
  for (const auto* curve : {&c, &z}) {
    for (double l : curve->lag_ms) lag_lo = std::min(lag_lo, l), lag_hi = std::max(lag_hi, l);
  }
  io::Figure fig;
  fig.title = title;
  fig.width_px = 1100;
  fig.panel_height_px = 270;
  auto mag = MakePanel("", "Frequency [Hz]", "Magnitude |G_yu| [mm/mm]");
  mag.series = {Drawn(m_style, m, m.magnitude), Drawn(c_style, c, c.magnitude), Drawn(z_style, z, z.magnitude)};
  auto pha = MakePanel("", "Frequency [Hz]", "Phase [deg]");
  pha.series = {Drawn(m_style, m, m.phase_deg), Drawn(c_style, c, c.phase_deg), Drawn(z_style, z, z.phase_deg)};
  auto lag = MakePanel("", "Frequency [Hz]", "Time lag -phase/ω [ms]");
  lag.series = {Drawn(m_style, m, m.lag_ms), Drawn(c_style, c, c.lag_ms), Drawn(z_style, z, z.lag_ms)};
  lag.y_range = std::make_pair(0.7 * lag_lo, 1.3 * lag_hi);
  auto coh = MakePanel("", "Frequency [Hz]", "Coherence γ² [-]");
  coh.series = {Drawn(m_style, m, m.coherence)};
  coh.y_range = std::make_pair(0.0, 1.05);
  // One legend, beside the first panel; every panel the same margins so the axes line up.
  const int right = io::KeyMarginChars({&mag});
  for (auto* p : {&mag, &pha, &lag, &coh}) {
    p->x_range = std::make_pair(0.0, fmax);
    p->shade_x = std::make_pair(continuous.fitted_lo_hz, continuous.fitted_hi_hz);
    p->key = p == &mag ? "outside right top" : "off";
    p->left_margin_chars = 12;
    p->right_margin_chars = right;
  }
  mag.title = fmt::format("shaded: the fitted band, {:.4g}-{:.4g} Hz", continuous.fitted_lo_hz, continuous.fitted_hi_hz);
  fig.panels = {mag, pha, lag, coh};
  return fig;
}

}  // namespace rths::ident
