#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"
#include "models/mr_damper.h"

namespace rths::diagnosis {

double Nrmse(std::span<const double> meas, std::span<const double> pred, std::size_t first) {
  if (meas.size() != pred.size()) throw Error("Nrmse", "lengths differ");
  double se = 0, sm = 0;
  for (std::size_t k = first; k < meas.size(); ++k) {
    const double e = meas[k] - pred[k];
    se += e * e;
    sm += meas[k] * meas[k];
  }
  return sm > 0 ? 100.0 * std::sqrt(se / sm) : std::nan("");
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

std::size_t Count(const std::vector<Data>& ds) {
  std::size_t n = 0;
  for (const auto& d : ds) n += d.size() - d.first;
  return n;
}

Channel::Channel(char ch, const std::vector<Data>* recs, const models::LinearServo* servo, const ForcePredictor* fp)
    : ch_(ch), recs_(recs), servo_(servo), fp_(fp) {
  for (const auto& d : *recs_) meas2_ += SumSq(ch_ == 'y' ? d.y : d.f, d.first);
}

std::vector<std::vector<double>> Channel::Predict(const models::EffectSet& set, double* scale_out,
                                                  std::optional<double> fixed_scale) const {
  std::vector<std::vector<double>> out;
  out.reserve(recs_->size());
  if (ch_ == 'y') {
    for (const auto& d : *recs_) out.push_back(PredictDisplacement(*servo_, set, d.u, d.f, nullptr, nullptr, d.y, d.first));
    return out;
  }
  for (const auto& d : *recs_) out.push_back(fp_->PredictUnscaled(d.motion, d.i, set));
  if (set.damper_scale) {
    double s = fixed_scale.value_or(0.0);
    if (!fixed_scale) {
      double num = 0, den = 0;
      for (std::size_t r = 0; r < recs_->size(); ++r) {
        const auto& d = (*recs_)[r];
        for (std::size_t k = d.first; k < d.size(); ++k) {
          num += d.f[k] * out[r][k];
          den += out[r][k] * out[r][k];
        }
      }
      s = den > 0 ? std::clamp(num / den, 0.1, 10.0) : 1.0;
    }
    for (auto& v : out)
      for (double& x : v) x *= s;
    if (scale_out) *scale_out = s;
  }
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

double Channel::NrmsePct(double sse) const { return meas2_ > 0 ? 100.0 * std::sqrt(sse / meas2_) : std::nan(""); }

std::span<const double> Channel::Meas(std::size_t r) const { return ch_ == 'y' ? (*recs_)[r].y : (*recs_)[r].f; }

}  // namespace stages
}  // namespace rths::diagnosis
