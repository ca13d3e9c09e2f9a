#include "ident/identify.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "signal/metrics.h"

namespace rths::ident {

std::size_t DefaultSegmentLength(std::size_t n, double dt_s, double segment_s) {
  std::size_t L = 0;
  if (segment_s > 0.0) {
    L = static_cast<std::size_t>(std::lround(segment_s / dt_s));
  } else {
    L = std::min<std::size_t>(static_cast<std::size_t>(std::lround(4.0 / dt_s)), 2 * n / 9);
  }
  return std::clamp<std::size_t>(L, std::min<std::size_t>(16, n), n);
}

Prediction PredictDisplacement(const PoleModel& model, double dt_s, std::span<const double> u_mm,
                               std::span<const double> y_mm, std::size_t first, std::size_t last) {
  if (u_mm.size() != y_mm.size())
    throw Error("PredictDisplacement", fmt::format("u and y differ in length ({} vs {})", u_mm.size(), y_mm.size()));
  if (!(first < last && last <= u_mm.size()))
    throw Error("PredictDisplacement", fmt::format("empty or out-of-range window [{}, {}) of {} samples", first,
                                                   last, u_mm.size()));
  Prediction p;
  p.y_mm = SimulateZoh(Discretise(model, dt_s), u_mm);
  const auto ym = y_mm.subspan(first, last - first);
  p.model_error_pct = signal::RmsErrorPercent(ym, std::span<const double>(p.y_mm).subspan(first, last - first));
  p.identity_error_pct = signal::RmsErrorPercent(ym, u_mm.subspan(first, last - first));
  return p;
}

IdentifyResult Identify(std::span<const double> u_mm, std::span<const double> y_mm, double dt_s,
                        const IdentifyOptions& options) {
  if (u_mm.size() != y_mm.size())
    throw Error("Identify", fmt::format("u and y differ in length ({} vs {})", u_mm.size(), y_mm.size()));
  IdentifyResult r;
  r.dt_s = dt_s;
  r.samples = u_mm.size();
  r.options = options;
  r.segment_length = DefaultSegmentLength(u_mm.size(), dt_s, options.segment_s);
  if (!(options.min_excitation >= 0.0 && options.min_excitation < 1.0))
    throw Error("Identify", fmt::format("min_excitation = {}: allowed [0, 1)", options.min_excitation));
  const auto spectra = signal::WelchCrossSpectra(u_mm, y_mm, dt_s, r.segment_length);
  r.frf = signal::H1FromSpectra(spectra);
  r.s_uu = spectra.s_uu;
  const auto in_band = [&](std::size_t i) {
    return r.frf.f_hz[i] >= options.fit.band_lo_hz && r.frf.f_hz[i] <= options.fit.band_hi_hz;
  };
  double peak = 0.0;
  for (std::size_t i = 0; i < r.s_uu.size(); ++i)
    if (in_band(i)) peak = std::max(peak, r.s_uu[i]);
  std::vector<double> coherence = r.frf.coherence;  // 0 = left out of the fit
  r.fitted_lo_hz = options.fit.band_hi_hz, r.fitted_hi_hz = options.fit.band_lo_hz;
  for (std::size_t i = 0; i < coherence.size(); ++i) {
    if (!in_band(i)) continue;
    if (r.s_uu[i] < options.min_excitation * peak) {
      coherence[i] = 0.0;
      ++r.unexcited_points;
    } else if (r.frf.f_hz[i] > 0.0) {
      r.fitted_lo_hz = std::min(r.fitted_lo_hz, r.frf.f_hz[i]);
      r.fitted_hi_hz = std::max(r.fitted_hi_hz, r.frf.f_hz[i]);
    }
  }
  r.fit = FitPoleModel(r.frf.f_hz, r.frf.h, coherence, options.fit);
  r.prediction = PredictDisplacement(r.fit.model, dt_s, u_mm, y_mm, 0, u_mm.size());
  return r;
}

std::string IdentifyResult::Report() const {
  std::string s;
  s += fmt::format("record: {} samples at dt = {} s ({:.4g} s)\n", samples, dt_s, static_cast<double>(samples) * dt_s);
  double cmin = 1.0, cmean = 0.0;
  int cn = 0;
  for (std::size_t i = 0; i < frf.f_hz.size(); ++i) {
    if (frf.f_hz[i] < options.fit.band_lo_hz || frf.f_hz[i] > options.fit.band_hi_hz) continue;
    cmin = std::min(cmin, frf.coherence[i]);
    cmean += frf.coherence[i];
    ++cn;
  }
  s += fmt::format("H1 estimate: Welch, Hann, 50 % overlap, {} segments of {} samples ({:.4g} s, df = {:.4g} Hz); "
                   "coherence over {}-{} Hz: mean {:.4f}, min {:.4f}\n",
                   frf.segments, segment_length, static_cast<double>(segment_length) * dt_s, frf.df_hz,
                   options.fit.band_lo_hz, options.fit.band_hi_hz, cn ? cmean / cn : 0.0, cmin);
  const char* weighting = options.fit.weighting == Weighting::kCoherence        ? "coherence^2"
                          : options.fit.weighting == Weighting::kInverseVariance ? "inverse variance"
                                                                                 : "uniform";
  s += fmt::format("fit: {} poles over {}-{} Hz, weights {}, {}\n", options.fit.poles, options.fit.band_lo_hz,
                   options.fit.band_hi_hz, weighting,
                   options.fit.zoh_dt_s > 0 ? fmt::format("ZOH-discretised model at dt = {} s", options.fit.zoh_dt_s)
                                            : std::string("continuous model (Eq. 15, no delay)"));
  if (unexcited_points > 0) {
    s += fmt::format("{} points of the band left out: input power below {:g} of its in-band peak (not excited); "
                     "fitted {:.4g}-{:.4g} Hz\n",
                     unexcited_points, options.min_excitation, fitted_lo_hz, fitted_hi_hz);
  }
  s += fit.Report();
  s += fmt::format("time domain (the model ZOH-discretised at dt, simulated on u from rest): Eq. 31 error of the "
                   "predicted y {:.3f} % (identity y = u: {:.3f} %)\n",
                   prediction.model_error_pct, prediction.identity_error_pct);
  return s;
}

namespace {
std::string Table(const PoleModel& m) {
  return fmt::format("{{ K = {:.10g}, p = {:.10g}, b = {:.10g}, c = {:.10g} }}", m.K, m.p, m.b[0], m.c[0]);
}
std::string Factors(const PoleModel& m) {
  std::string s = fmt::format("K = {:.10g}; denominator", m.K);
  if (m.p > 0) s += fmt::format(" (s + {:.10g})", m.p);
  for (std::size_t j = 0; j < m.b.size(); ++j) s += fmt::format(" (s^2 + {:.10g} s + {:.10g})", m.b[j], m.c[j]);
  return s;
}
}  // namespace

std::string ScenarioFragment(const IdentifyResult& continuous, const IdentifyResult& zoh, const std::string& title) {
  const auto& mc = continuous.fit.model;
  const auto& mz = zoh.fit.model;
  std::string s = "# " + title + "\n";
  const std::string zoh_note = fmt::format(
      "# ZOH-consistent fit: simulated with a zero-order hold at dt = {} s it reproduces the record\n"
      "# (Eq. 31 error {:.3g} %; fit error {:.3g} %; DC gain {:.5g}, DC lag {:.4g} ms)\n",
      zoh.dt_s, zoh.prediction.model_error_pct, 100.0 * zoh.fit.rms_rel_error, mz.DcGain(), 1e3 * mz.DcLagS());
  const std::string cont_note = fmt::format(
      "# Eq. 15 fitted to the measured G_yu as the paper does (it holds the D/A hold's half-sample\n"
      "# lag, as the lab's Eqs. 28-30 hold their converters'; fit error {:.3g} %; DC gain {:.5g}, DC lag {:.4g} ms)\n",
      100.0 * continuous.fit.rms_rel_error, mc.DcGain(), 1e3 * mc.DcLagS());
  const bool three = mc.Order() == 3 && mc.b.size() == 1 && mz.Order() == 3 && mz.b.size() == 1;
  if (!three) {
    s += fmt::format("# {} poles: a scenario holds 3-pole models only.\n", mc.Order());
    s += zoh_note + "# " + Factors(mz) + "\n" + cont_note + "# " + Factors(mc) + "\n";
    return s;
  }
  s += fmt::format("\n[run]\n# the record's step: `rths run` and `rths design` of this file use it\ndt_s = {}\n", zoh.dt_s);
  s += "\n[plant]\n" + zoh_note + "actuator = " + Table(mz) + "\n";
  s += "\n[controller]\n" + cont_note + "model = " + Table(mc) + "\n";
  return s;
}

}  // namespace rths::ident
