#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/search.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"
#include "models/mr_damper.h"
#include "models/rig_effects.h"
#include "signal/metrics.h"

namespace rths::diagnosis {

double Nrmse(std::span<const double> meas, std::span<const double> pred, std::size_t first) {
  if (meas.size() != pred.size()) throw Error("Nrmse", "lengths differ");
  signal::RmsErrorAccumulator eq31;  // Eq. 31 with the measurement in the role of r
  for (std::size_t k = first; k < meas.size(); ++k) eq31.Add(meas[k], pred[k]);
  return eq31.Percent();
}

double ShrinkPct(double before_pct, double after_pct) { return 100.0 * (1.0 - after_pct / before_pct); }

namespace {

double Sse(std::span<const double> m, std::span<const double> p, std::size_t first) {
  double s = 0;
  for (std::size_t k = first; k < m.size(); ++k) {
    const double e = m[k] - p[k];
    s += e * e;
  }
  return s;
}

}  // namespace

namespace stages {

Data Prepare(const io::RigRecord& r, const Options& o) {
  Data d;
  d.source = r.source;
  d.dt = r.dt_s;
  d.u = r.u_mm;
  d.y = r.y_mm;
  d.f = r.f_kN;
  d.i = r.Command();  // the current, or the voltage of a record without one
  d.first = std::min<std::size_t>(d.size() / 2, static_cast<std::size_t>(std::lround(o.warmup_s / r.dt_s)));
  // The force channel's motion is made once y is diagnosed (ModelAidedMotion).
  return d;
}

void ExtendWarmupIfMoving(Data* d, const NominalModel& model, std::vector<std::string>* notes) {
  const std::size_t n = d->size();
  if (n < 20) return;
  double umax = 0.0, ustart = 0.0;
  for (std::size_t k = 0; k < n; ++k) umax = std::max(umax, std::abs(d->u[k]));
  for (std::size_t k = 0; k < 10; ++k) ustart = std::max(ustart, std::abs(d->u[k]));
  if (!(ustart > tuning::kMovingStartFraction * umax)) return;
  // The travel the damper needs to forget its start, and the current dynamics' settling time.
  double travel_mm = 0.0, settle_s = 0.0;
  if (model.has_damper) {
    double imax = 0.0;
    for (double i : d->i) imax = std::max(imax, i);
    for (double i : {0.0, imax}) {
      const auto c = models::CoefficientsAt(model.damper, i);
      if (c.beta + c.gamma > 0.0) travel_mm = std::max(travel_mm, 1.0 / std::sqrt(c.A * (c.beta + c.gamma)));
    }
    travel_mm *= tuning::kStartTravelFactor;
    if (model.current_dynamics && d->i[0] != 0.0) {  // a current on at the start may be mid-transition
      const auto& cd = model.current_driver;
      const double tau = cd.kind == models::CurrentFilter::kFirstOrder ? 1.0 / cd.eta_1_s : 1.0 / cd.lag_pole_rad_s;
      settle_s = tuning::kStartTimeConstants * tau;
    }
  }
  std::size_t k = std::max(d->first, static_cast<std::size_t>(std::ceil(settle_s / d->dt)));
  double travelled = 0.0;
  for (std::size_t j = 1; j < k && j < n; ++j) travelled += std::abs(d->u[j] - d->u[j - 1]);
  for (; k < n / 2 && travelled < travel_mm; ++k) travelled += std::abs(d->u[k] - d->u[k - 1]);
  k = std::min(k, n / 2);
  if (k <= d->first) return;
  notes->push_back(fmt::format("{}: starts in motion (|u| {:.3g} mm in its first 10 samples): the sums start at "
                               "{:.3f} s instead of {:.3f} s, once u has travelled {:.3g} mm and {:.3g} s have passed "
                               "(the model starts at rest; its damper and current dynamics forget the difference)",
                               d->source, ustart, static_cast<double>(k) * d->dt,
                               static_cast<double>(d->first) * d->dt, travel_mm, settle_s));
  d->first = k;
}

void EstimateCurrentStart(Data* d, const ForcePredictor& fp, const NominalModel& model, std::vector<std::string>* notes) {
  if (!model.has_damper || !model.current_dynamics || d->size() < 4 || d->i[0] == 0.0) return;
  if (d->motion.v_mm_s.size() != d->size()) throw Error(d->source, "EstimateCurrentStart needs the damper's motion");
  const auto& cd = model.current_driver;
  const double tau_s = cd.kind == models::CurrentFilter::kFirstOrder ? 1.0 / cd.eta_1_s : 1.0 / cd.lag_pole_rad_s;
  const std::size_t n = std::min(d->size(), d->first + static_cast<std::size_t>(std::ceil(tuning::kStartTimeConstants * tau_s / d->dt)) + 1);
  if (n <= d->first + 1) return;
  // The record's first n samples (the transient lives there).
  SmoothedMotion mo;
  mo.x_mm.assign(d->motion.x_mm.begin(), d->motion.x_mm.begin() + static_cast<std::ptrdiff_t>(n));
  mo.v_mm_s.assign(d->motion.v_mm_s.begin(), d->motion.v_mm_s.begin() + static_cast<std::ptrdiff_t>(n));
  if (d->motion.a_mm_s2.size() == d->size())
    mo.a_mm_s2.assign(d->motion.a_mm_s2.begin(), d->motion.a_mm_s2.begin() + static_cast<std::ptrdiff_t>(n));
  const std::span<const double> i(d->i.data(), n);
  double imax = 0.0;
  for (double v : d->i) imax = std::max(imax, v);
  if (!(imax > 0.0)) return;
  // The residual after the best force scale (least squares over the window): a damper stronger or
  // weaker than the model (damper_scale, not yet known here) must not pass for a current start.
  auto sse = [&](double i0) {
    const auto f = fp.PredictUnscaled(mo, i, {}, i0);
    double ff = 0.0, mf = 0.0, mm = 0.0;
    for (std::size_t k = d->first; k < n; ++k) ff += f[k] * f[k], mf += d->f[k] * f[k], mm += d->f[k] * d->f[k];
    const double s = ff > 0.0 ? mm - mf * mf / ff : mm;
    return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
  };
  double best = 0.0;
  const ParamSpec range{"i_start_A", 0.0, imax, false, tuning::kStartCurrentGrid};
  const double i0 = Minimise1D(sse, range, tuning::kStartCurrentIters, &best, {d->i[0], 0.0});
  // The start must tell: a window where the damper hardly moves (its force does not depend on the
  // current) or whose start fits about as well at the first command keeps that (no claim).
  if (!(best < tuning::kStartCurrentGain * sse(d->i[0]))) return;
  d->i_start_A = i0;
  if (notes != nullptr && std::abs(i0 - d->i[0]) > tuning::kStartCurrentNote * imax)
    notes->push_back(fmt::format("{}: the current command is {:.3g} at its first sample, but the current dynamics start as "
                                 "if {:.3g} had been held before (fitted on its first {:.3g} s: the driver {}); the model "
                                 "starts there",
                                 d->source, d->i[0], i0, static_cast<double>(n) * d->dt,
                                 i0 < tuning::kStartCurrentNote * imax ? "started from rest" : "was mid-transition"));
}

std::size_t Count(const std::vector<Data>& ds) {
  std::size_t n = 0;
  for (const auto& d : ds) n += d.size() - d.first;
  return n;
}

Channel::Channel(char ch, const std::vector<Data>* recs, const models::LinearServo* servo, const ForcePredictor* fp)
    : ch_(ch), recs_(recs), servo_(servo), fp_(fp) {
  for (const auto& d : *recs_) meas2_ += SumSq(ch_ == 'y' ? d.y : d.f, d.first);
}

namespace {

/// The shift of channel_skew [s] (0 if off).
double SkewS(const models::EffectSet& set) { return set.channel_skew ? 1e-3 * set.channel_skew->skew_ms : 0.0; }

/// load_cell_inertia's regressor: 1e-6 x the shifted acceleration [kN/kg].
std::vector<double> InertiaRegressor(const Data& d, const models::EffectSet& set) {
  if (d.acc_mm_s2.size() != d.size()) throw Error(d.source, "the damper's acceleration is not set (load_cell_inertia)");
  std::vector<double> a = models::ShiftSamples(d.acc_mm_s2, SkewS(set), d.dt);
  for (double& x : a) x *= 1e-6;
  return a;
}

/// A damper force shifted by channel_skew (a copy).
std::vector<double> Skewed(const std::vector<double>& damper, const Data& d, const models::EffectSet& set) {
  return set.channel_skew ? models::ShiftSamples(damper, SkewS(set), d.dt) : damper;
}

/// f = shift(scale fhat) + mass x regressor (the set's values).
std::vector<double> WithLinearTerms(std::vector<double> f, const Data& d, const models::EffectSet& set) {
  if (set.damper_scale)
    for (double& v : f) v *= set.damper_scale->scale;
  if (set.load_cell_inertia) {
    const auto a = InertiaRegressor(d, set);
    for (std::size_t k = 0; k < f.size(); ++k) f[k] += set.load_cell_inertia->mass_kg * a[k];
  }
  return f;
}

/// The search ranges of the linear terms (models::kEffects; the least squares are clipped to them).
constexpr double kScaleLo = 0.1, kScaleHi = 10.0, kMassLo = 0.01, kMassHi = 1e4;

}  // namespace

std::vector<double> PredictForce(const Data& d, const ForcePredictor& fp, const models::EffectSet& set) {
  return WithLinearTerms(Skewed(fp.PredictUnscaled(d.motion, d.i, set, d.i_start_A), d, set), d, set);
}

const std::vector<std::vector<double>>& Channel::DamperForces(const models::EffectSet& set) const {
  const double key = set.current_lag ? set.current_lag->tau_ms : -1.0;
  for (const auto& [k, f] : damper_cache_)
    if (k == key) return f;
  std::vector<std::vector<double>> f;
  f.reserve(recs_->size());
  for (const auto& d : *recs_) f.push_back(fp_->PredictUnscaled(d.motion, d.i, set, d.i_start_A));
  if (damper_cache_.size() == kDamperCache) damper_cache_.erase(damper_cache_.begin());
  damper_cache_.emplace_back(key, std::move(f));
  return damper_cache_.back().second;
}

std::vector<std::vector<double>> Channel::Predict(const models::EffectSet& set, LinearForce* fitted,
                                                  bool hold_linear) const {
  std::vector<std::vector<double>> out;
  out.reserve(recs_->size());
  if (ch_ == 'y') {
    for (const auto& d : *recs_) out.push_back(PredictDisplacement(*servo_, set, d.u, d.f, nullptr, nullptr, d.y, d.first));
    return out;
  }
  const bool scale = set.damper_scale.has_value(), mass = set.load_cell_inertia.has_value();
  const auto& damper = DamperForces(set);
  if (hold_linear || (!scale && !mass)) {
    for (std::size_t r = 0; r < recs_->size(); ++r)
      out.push_back(WithLinearTerms(Skewed(damper[r], (*recs_)[r], set), (*recs_)[r], set));
    return out;
  }
  // Least squares of f on s fhat + m a over the records' sums (the terms absent held at 1 and 0).
  std::vector<std::vector<double>> acc;
  double srr = 0, sra = 0, saa = 0, sfr = 0, sfa = 0;
  for (std::size_t j = 0; j < recs_->size(); ++j) {
    const Data& d = (*recs_)[j];
    out.push_back(Skewed(damper[j], d, set));
    acc.push_back(mass ? InertiaRegressor(d, set) : std::vector<double>(d.size(), 0.0));
    const auto& r = out.back();
    const auto& a = acc.back();
    for (std::size_t k = d.first; k < d.size(); ++k) {
      srr += r[k] * r[k], sra += r[k] * a[k], saa += a[k] * a[k];
      sfr += d.f[k] * r[k], sfa += d.f[k] * a[k];
    }
  }
  LinearForce lin;
  auto mass_given_scale = [&](double sc) { return saa > 0 ? std::clamp((sfa - sc * sra) / saa, kMassLo, kMassHi) : kMassLo; };
  auto scale_given_mass = [&](double m) { return srr > 0 ? std::clamp((sfr - m * sra) / srr, kScaleLo, kScaleHi) : 1.0; };
  if (scale && mass) {
    const double det = srr * saa - sra * sra;
    double sc = det > 0 ? (sfr * saa - sfa * sra) / det : 1.0;
    double m = det > 0 ? (srr * sfa - sra * sfr) / det : kMassLo;
    if (!(m >= kMassLo && m <= kMassHi)) m = std::clamp(m, kMassLo, kMassHi), sc = scale_given_mass(m);
    if (!(sc >= kScaleLo && sc <= kScaleHi)) sc = std::clamp(sc, kScaleLo, kScaleHi), m = mass_given_scale(sc);
    lin = {sc, m};
  } else if (scale) {
    lin = {scale_given_mass(0.0), 0.0};
  } else {
    // f - fhat = m a (no scale: 1).
    lin = {1.0, saa > 0 ? std::clamp((sfa - sra) / saa, kMassLo, kMassHi) : kMassLo};
  }
  for (std::size_t r = 0; r < out.size(); ++r)
    for (std::size_t k = 0; k < out[r].size(); ++k) out[r][k] = lin.scale * out[r][k] + lin.mass_kg * acc[r][k];
  if (fitted) *fitted = lin;
  return out;
}

double Channel::Sse(const std::vector<std::vector<double>>& pred) const {
  double s = 0;
  for (std::size_t r = 0; r < recs_->size(); ++r) {
    const auto& d = (*recs_)[r];
    s += diagnosis::Sse(ch_ == 'y' ? d.y : d.f, pred[r], d.first);
  }
  return s;
}

double Channel::NrmsePct(double sse) const {
  return signal::RmsErrorAccumulator{sse, meas2_, 0}.Percent();  // Eq. 31 of the sums
}

std::span<const double> Channel::Meas(std::size_t r) const { return ch_ == 'y' ? (*recs_)[r].y : (*recs_)[r].f; }

}  // namespace stages
}  // namespace rths::diagnosis
