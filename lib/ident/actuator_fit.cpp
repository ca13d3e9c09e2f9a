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

}  // namespace

io::Figure ActuatorFit::Bode(const std::string& title) const {
  const double fmax = std::min(50.0, 0.5 / continuous.dt_s);
  std::vector<double> grid;
  for (int i = 1; i <= 500; ++i) grid.push_back(fmax * i / 500.0);
  std::vector<io::BodeTrace> traces(3);
  traces[0].curve = MeasuredCurve(continuous, fmax);
  traces[0].style = io::MakeSeries("measured H1", io::ReadableColors()[0]);
  traces[0].style.width = 2.0;
  traces[0].coherence_style = traces[0].style;
  traces[1].curve = BodeFromModel("Eq. 15 fit", continuous.fit.model, grid, 0.0);
  traces[1].style = io::MakeSeries("Eq. 15 fit", "#000000", 2);
  traces[1].style.width = 2.0;
  traces[2].curve = BodeFromModel("ZOH-consistent fit", zoh.fit.model, grid, zoh.dt_s);
  traces[2].style = io::MakeSeries("ZOH-consistent fit", io::ReadableColors()[1], 3);
  traces[2].style.width = 3.5;
  // The lag axis: the models' time-lag range [ms] (the measured lag scatters at low f).
  double lag_lo = 1e300, lag_hi = -1e300;
  for (std::size_t i = 1; i < traces.size(); ++i)
    for (double l : traces[i].curve.lag_ms) lag_lo = std::min(lag_lo, l), lag_hi = std::max(lag_hi, l);
  io::BodeLayout layout;
  layout.f_range_hz = {0.0, fmax};
  layout.magnitude_title =
      fmt::format("shaded: the fitted band, {:.4g}-{:.4g} Hz", continuous.fitted_lo_hz, continuous.fitted_hi_hz);
  layout.magnitude_label = "Magnitude |G_yu| [mm/mm]";
  layout.lag_label = "Time lag -phase/ω [ms]";
  layout.lag_range_ms = std::make_pair(0.7 * lag_lo, 1.3 * lag_hi);
  layout.coherence_panel = true;
  layout.left_margin_chars = 12;
  layout.shade_hz = std::make_pair(continuous.fitted_lo_hz, continuous.fitted_hi_hz);
  io::Figure fig = io::BodeFigure(layout, traces);
  fig.title = title;
  fig.width_px = 1100;
  fig.panel_height_px = 270;
  return fig;
}

}  // namespace rths::ident
