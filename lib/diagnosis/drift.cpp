// RemoveSensorDrift of stages.h: --detrend as a sensor's drift, removed from the measurement only.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"
#include "signal/zero_phase.h"

namespace rths::diagnosis::stages {

namespace {

/// The slow part of meas - pred: ZeroPhaseLowpass at tuning::kDriftHz over the residual extended
/// by even reflection, n - 1 samples each side. (Odd reflection, as SmoothMotion uses for the
/// motion, mirrors about the end samples: at 0.1 Hz one noisy end sample becomes a step the filter
/// spreads over seconds, a false drift of a quarter of the noise.)
std::vector<double> SlowPart(std::span<const double> meas, const std::vector<double>& pred, double dt) {
  std::vector<double> res(meas.size());
  for (std::size_t k = 0; k < res.size(); ++k) res[k] = meas[k] - pred[k];
  return signal::ZeroPhaseLowpass(res, dt, std::min(tuning::kDriftHz, 0.25 / dt), 2, res.size(), signal::Reflection::kEven);
}

}  // namespace

bool ExcessIsSlow(const ChannelState& s, double none_ratio) {
  if (!s.structured || !(s.var_floor > 0.0)) return false;
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& [c, pred] : {std::pair{&s.train, &s.pred_train}, std::pair{&s.test, &s.nom_test}}) {
    for (std::size_t r = 0; r < c->recs().size(); ++r) {
      const auto meas = c->Meas(r);
      const auto slow = SlowPart(meas, (*pred)[r], c->recs()[r].dt);
      for (std::size_t k = c->recs()[r].first; k < meas.size(); ++k, ++n) {
        const double e = meas[k] - (*pred)[r][k] - slow[k];
        sum += e * e;
      }
    }
  }
  return n > 0 && sum / static_cast<double>(n) / s.var_floor <= none_ratio;
}

void RemoveSensorDrift(char ch, std::vector<Data>* recs, const models::LinearServo& servo, const ForcePredictor* fp,
                       const models::EffectSet& effects, std::vector<std::string>* notes) {
  for (auto& d : *recs) {
    const std::vector<double> pred =
        ch == 'y' ? PredictDisplacement(servo, effects, d.u, d.f, nullptr, nullptr, d.y, d.first) : PredictForce(d, *fp, effects);
    std::vector<double>& meas = ch == 'y' ? d.y : d.f;
    const auto drift = SlowPart(meas, pred, d.dt);
    double ss = 0.0, lo = drift.empty() ? 0.0 : drift[0], hi = lo;
    for (std::size_t k = 0; k < meas.size(); ++k) {
      meas[k] -= drift[k];
      ss += drift[k] * drift[k];
      lo = std::min(lo, drift[k]);
      hi = std::max(hi, drift[k]);
    }
    const double rms = drift.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(drift.size()));
    if (notes == nullptr) continue;
    notes->push_back(fmt::format("{}: sensor_drift removed from {} (the model's residual below {:g} Hz): "
                                 "{:.4g} {} rms, {:.4g} {} from its lowest to its highest",
                                 d.source, ch, tuning::kDriftHz, rms, ch == 'y' ? "mm" : "kN", hi - lo,
                                 ch == 'y' ? "mm" : "kN"));
  }
}

}  // namespace rths::diagnosis::stages
