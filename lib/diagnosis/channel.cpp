#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"

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
    for (const auto& d : *recs_) out.push_back(PredictDisplacement(*servo_, set, d.u, d.f));
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
