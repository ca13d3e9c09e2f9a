#include "ident/measurement_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.h"
#include "ident/damper_fit.h"
#include "models/rig_effects.h"
#include "signal/derivative.h"

namespace rths::ident {

namespace {

/// One record's data for the fit.
struct Rec {
  const io::RigRecord* r;
  std::vector<double> F, a;  // the damper's force [kN]; 1e-6 x the acceleration [kN/kg]
  double w;                  // 1 / sum f^2
};

/// m at skew s (the options' mode), and the cost J(s, m).
struct Eval {
  double m = 0, J = 0, saa = 0;  // saa: sum w (shifted a)^2, J'' = 2 saa along m
};

Eval Evaluate(const std::vector<Rec>& recs, double skew_s, const MeasurementOptions& o) {
  std::vector<std::vector<double>> Fs(recs.size()), as(recs.size());
  double sfa = 0, saa = 0;
  for (std::size_t j = 0; j < recs.size(); ++j) {
    const auto& q = recs[j];
    Fs[j] = models::ShiftSamples(q.F, skew_s, q.r->dt_s);
    if (o.inertia == MeasurementMode::kOff) continue;
    as[j] = models::ShiftSamples(q.a, skew_s, q.r->dt_s);
    for (std::size_t k = 0; k < Fs[j].size(); ++k) {
      sfa += q.w * (q.r->f_kN[k] - Fs[j][k]) * as[j][k];
      saa += q.w * as[j][k] * as[j][k];
    }
  }
  Eval e;
  e.saa = saa;
  if (o.inertia == MeasurementMode::kGiven) e.m = o.mass_kg;
  else if (o.inertia == MeasurementMode::kAuto) e.m = saa > 0 ? std::max(0.0, sfa / saa) : 0.0;
  for (std::size_t j = 0; j < recs.size(); ++j) {
    const auto& q = recs[j];
    double s = 0.0;
    for (std::size_t k = 0; k < Fs[j].size(); ++k) {
      const double pred = Fs[j][k] + (as[j].empty() ? 0.0 : e.m * as[j][k]);
      s += (q.r->f_kN[k] - pred) * (q.r->f_kN[k] - pred);
    }
    e.J += q.w * s;
  }
  return e;
}

/// Integrated correlation time of the residual of the fit (autocovariances pooled over the records,
/// summed up to the first non-positive correlation, at most 2000 lags and a quarter of a record).
double CorrelationTime(const std::vector<Rec>& recs, double skew_s, double m) {
  std::vector<std::vector<double>> res;
  std::size_t nmin = std::numeric_limits<std::size_t>::max();
  for (const auto& q : recs) {
    const auto Fs = models::ShiftSamples(q.F, skew_s, q.r->dt_s);
    const auto as = models::ShiftSamples(q.a, skew_s, q.r->dt_s);
    std::vector<double> e(Fs.size());
    for (std::size_t k = 0; k < e.size(); ++k) e[k] = q.r->f_kN[k] - Fs[k] - (as.empty() ? 0.0 : m * as[k]);
    nmin = std::min(nmin, e.size());
    res.push_back(std::move(e));
  }
  const std::size_t lmax = std::min<std::size_t>(2000, nmin / 4);
  double c0 = 0.0;
  for (const auto& e : res)
    for (double x : e) c0 += x * x;
  if (!(c0 > 0.0)) return 1.0;
  double tau = 1.0;
  for (std::size_t l = 1; l <= lmax; ++l) {
    double c = 0.0;
    for (const auto& e : res)
      for (std::size_t k = l; k < e.size(); ++k) c += e[k] * e[k - l];
    if (c <= 0.0) break;
    tau += 2.0 * c / c0;
  }
  return tau;
}

}  // namespace

std::vector<double> SmoothAcceleration(const io::RigRecord& r, double cutoff_hz) {
  return signal::Derivative(SmoothVelocity(r.y_mm, r.dt_s, cutoff_hz), r.dt_s);
}

std::vector<double> MeasurementFit::Measured(std::span<const double> F_kN, const io::RigRecord& r, double cutoff_hz) const {
  std::vector<double> f(F_kN.begin(), F_kN.end());
  if (mass_kg != 0.0) {
    const auto a = SmoothAcceleration(r, cutoff_hz);
    for (std::size_t k = 0; k < f.size(); ++k) f[k] += 1e-6 * mass_kg * a[k];
  }
  return models::ShiftSamples(f, 1e-3 * skew_ms, r.dt_s);
}

io::RigRecord MeasurementFit::DamperForceRecord(const io::RigRecord& r, double cutoff_hz) const {
  io::RigRecord out = r;
  out.f_kN = models::ShiftSamples(r.f_kN, -1e-3 * skew_ms, r.dt_s);
  if (mass_kg != 0.0) {
    const auto a = SmoothAcceleration(r, cutoff_hz);
    for (std::size_t k = 0; k < out.f_kN.size(); ++k) out.f_kN[k] -= 1e-6 * mass_kg * a[k];
  }
  return out;
}

std::string MeasurementFit::Report() const {
  std::string s;
  auto how = [](MeasurementMode m) { return m == MeasurementMode::kGiven ? "given" : "fitted"; };
  if (options.skew != MeasurementMode::kOff)
    s += fmt::format("  channel skew (the force channel's lag behind the displacement's): {:.4g} ms{} ({})\n", skew_ms,
                     skew_se_ms > 0 ? fmt::format(" +- {:.2g} ms", skew_se_ms) : "", how(options.skew));
  if (skew_at_range_end)
    s += fmt::format("    the skew is at an end of its range (+-{:g} ms): the records ask for more, which is no DAQ's skew "
                     "(the model's lag is wrong, or the force and motion columns are not paired sample by sample)\n",
                     kMaxSkewMs);
  if (profiled && (skew_se_ms > 0 || mass_se_kg > 0))
    s += "    (+- one standard error, from the cost's profile with the damper model refitted at either side)\n";
  if (options.inertia != MeasurementMode::kOff) {
    s += fmt::format("  load-cell inertia (the mass between load cell and damper): {:.4g} kg{} ({})\n", mass_kg,
                     mass_se_kg > 0 ? fmt::format(" +- {:.2g} kg", mass_se_kg) : "", how(options.inertia));
    if (mass_unresolved)
      s += "    the records' acceleration is too small to tell this mass from noise (less than 2 standard errors)\n";
  }
  return s;
}

std::string MeasurementFit::Toml() const {
  std::string s;
  if (options.skew != MeasurementMode::kOff)
    s += fmt::format("\n# the force channel lags the displacement channel by {:.6g} ms (+- {:.2g} ms)\n"
                     "[plant.effects.channel_skew]\nskew_ms = {}\n",
                     skew_ms, skew_se_ms, TomlFloat(skew_ms));
  if (options.inertia != MeasurementMode::kOff)
    s += fmt::format("\n# the mass between the load cell and the damper: {:.6g} kg (+- {:.2g} kg)\n"
                     "[plant.effects.load_cell_inertia]\nmass_kg = {}\n",
                     mass_kg, mass_se_kg, TomlFloat(mass_kg));
  return s;
}

MeasurementFit FitMeasurement(const std::vector<io::RigRecord>& records, const std::vector<std::vector<double>>& F,
                              const std::vector<double>& cutoff_hz, const MeasurementOptions& o) {
  if (F.size() != records.size() || cutoff_hz.size() != records.size())
    throw Error("FitMeasurement", "one force prediction and one cut-off per record");
  if (o.skew == MeasurementMode::kGiven && !(std::abs(o.skew_ms) <= kMaxSkewMs))
    throw Error("--skew", fmt::format("{} ms: must be in [-{:g}, {:g}] ms", o.skew_ms, kMaxSkewMs, kMaxSkewMs));
  if (o.inertia == MeasurementMode::kGiven && !(o.mass_kg >= 0.0 && std::isfinite(o.mass_kg)))
    throw Error("--inertia", fmt::format("{} kg: must be >= 0", o.mass_kg));
  std::vector<Rec> recs;
  std::size_t n = 0;
  for (std::size_t j = 0; j < records.size(); ++j) {
    const auto& r = records[j];
    if (F[j].size() != r.size()) throw Error(RecordName(r), "the force prediction's length differs from the record's");
    Rec q{&r, F[j], {}, ForceWeight(r)};
    if (o.inertia != MeasurementMode::kOff) {
      q.a = SmoothAcceleration(r, cutoff_hz[j]);
      for (double& x : q.a) x *= 1e-6;
    }
    n += r.size();
    recs.push_back(std::move(q));
  }
  MeasurementFit fit;
  fit.options = o;
  double s = o.skew == MeasurementMode::kGiven ? 1e-3 * o.skew_ms : 0.0;  // [s]
  if (o.skew == MeasurementMode::kAuto) {
    // Grid over the range, then golden section between the best point's neighbours.
    const double lo = -1e-3 * kMaxSkewMs, hi = 1e-3 * kMaxSkewMs, step = (hi - lo) / (kSkewGrid - 1);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kSkewGrid; ++i) {
      const double x = lo + step * i, J = Evaluate(recs, x, o).J;
      if (J < best) best = J, s = x;
    }
    double a = std::max(lo, s - step), b = std::min(hi, s + step);
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    double Jc = Evaluate(recs, c, o).J, Jd = Evaluate(recs, d, o).J;
    for (int it = 0; it < 40; ++it) {
      if (Jc < Jd) b = d, d = c, Jd = Jc, c = b - g * (b - a), Jc = Evaluate(recs, c, o).J;
      else a = c, c = d, Jc = Jd, d = a + g * (b - a), Jd = Evaluate(recs, d, o).J;
    }
    const double x = 0.5 * (a + b);
    if (Evaluate(recs, x, o).J < best) s = x;
  }
  const Eval e = Evaluate(recs, s, o);
  fit.skew_ms = 1e3 * s;
  fit.skew_at_range_end = o.skew == MeasurementMode::kAuto && std::abs(fit.skew_ms) >= kMaxSkewMs * (1.0 - 1e-9);
  fit.mass_kg = e.m;
  const double tau = CorrelationTime(recs, s, e.m);
  const double sigma2 = e.J / static_cast<double>(std::max<std::size_t>(n, 1));
  fit.cost = e.J, fit.sigma2 = sigma2, fit.tau = tau;
  if (o.skew == MeasurementMode::kAuto) {
    const double h = 0.05 * records.front().dt_s;
    const double Jp = Evaluate(recs, s + h, o).J, Jm = Evaluate(recs, s - h, o).J;
    const double curv = (Jp - 2.0 * e.J + Jm) / (h * h);
    fit.skew_se_ms = curv > 0 ? 1e3 * std::sqrt(2.0 * sigma2 * tau / curv) : std::numeric_limits<double>::infinity();
  }
  if (o.inertia == MeasurementMode::kAuto) {
    fit.mass_se_kg = e.saa > 0 ? std::sqrt(sigma2 * tau / e.saa) : std::numeric_limits<double>::infinity();
    fit.mass_unresolved = !(fit.mass_kg > 2.0 * fit.mass_se_kg);
  }
  return fit;
}

}  // namespace rths::ident
