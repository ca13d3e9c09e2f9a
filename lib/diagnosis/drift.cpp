// RemoveSensorDrift of stages.h: --detrend as a sensor's drift, removed from the measurement only.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"
#include "signal/butterworth.h"

namespace rths::diagnosis::stages {

namespace {

/// The slow part of meas - pred: a 2nd-order Butterworth low-pass at tuning::kDriftHz run forward
/// and backward over the residual extended at both ends by even reflection. (Odd reflection, as
/// SmoothMotion uses for the motion, mirrors about the end samples: at 0.1 Hz one noisy end sample
/// becomes a step the filter spreads over seconds, a false drift of a quarter of the noise.)
std::vector<double> SlowPart(std::span<const double> meas, const std::vector<double>& pred, double dt) {
  const std::size_t n = meas.size();
  const auto sos = signal::ButterworthLowpass(2, std::min(tuning::kDriftHz, 0.25 / dt), 1.0 / dt);
  const std::size_t pad = n - 1;
  std::vector<double> w;
  w.reserve(n + 2 * pad);
  for (std::size_t j = pad; j >= 1; --j) w.push_back(meas[j] - pred[j]);
  for (std::size_t k = 0; k < n; ++k) w.push_back(meas[k] - pred[k]);
  for (std::size_t j = 1; j <= pad; ++j) w.push_back(meas[n - 1 - j] - pred[n - 1 - j]);
  for (int pass = 0; pass < 2; ++pass) {
    auto st = signal::SosAtRest(sos);
    for (double& v : w) v = signal::SosStep(sos, &st, v);
    std::reverse(w.begin(), w.end());
  }
  return {w.begin() + static_cast<std::ptrdiff_t>(pad), w.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

}  // namespace

bool ExcessIsSlow(const ChannelState& s, double none_ratio) {
  if (!s.structured || !(s.var_floor > 0.0)) return false;
  double sum = 0.0;
  std::size_t n = 0;
  for (const Channel* c : {&s.train, &s.test}) {
    const auto pred = c->Predict({});
    for (std::size_t r = 0; r < c->recs().size(); ++r) {
      const auto meas = c->Meas(r);
      const auto slow = SlowPart(meas, pred[r], c->recs()[r].dt);
      for (std::size_t k = c->recs()[r].first; k < meas.size(); ++k, ++n) {
        const double e = meas[k] - pred[r][k] - slow[k];
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
        ch == 'y' ? PredictDisplacement(servo, effects, d.u, d.f) : fp->Predict(d.motion, d.i, effects);
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
