#include "models/rig_effects.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/error.h"

namespace rths::models {
namespace {

void Check(bool ok, std::string_view where, std::string_view effect, std::string_view key,
           double value, std::string_view range) {
  if (ok && std::isfinite(value)) return;
  throw Error(std::string(where) + (where.empty() ? "" : ": ") + "effects." +
                  std::string(effect) + "." + std::string(key),
              "value " + std::to_string(value) + " is out of range; allowed " +
                  std::string(range));
}

}  // namespace

bool EffectSet::Empty() const {
  return !pure_delay && !gain_error && !load_coupling && !oil_column_resonance &&
         !coulomb_friction && !backlash && !servovalve_saturation && !sensor_noise &&
         !current_lag && !damper_scale;
}

void EffectSet::Validate(double dt_s, std::string_view where) const {
  if (pure_delay)
    Check(pure_delay->tau_ms >= 0 && pure_delay->tau_ms <= 100, where, "pure_delay", "tau_ms",
          pure_delay->tau_ms, "[0, 100] ms");
  if (gain_error)
    Check(gain_error->gain >= 0.5 && gain_error->gain <= 2, where, "gain_error", "gain",
          gain_error->gain, "[0.5, 2]");
  if (load_coupling)
    Check(std::abs(load_coupling->compliance_mm_per_kN) <= 1, where, "load_coupling",
          "compliance_mm_per_kN", load_coupling->compliance_mm_per_kN, "[-1, 1] mm/kN");
  if (oil_column_resonance) {
    const double f_max = 0.45 / dt_s;
    Check(oil_column_resonance->f_hz > 0 && oil_column_resonance->f_hz < f_max, where,
          "oil_column_resonance", "f_hz", oil_column_resonance->f_hz,
          "(0, " + std::to_string(f_max) + ") Hz (0.45 / dt)");
    Check(oil_column_resonance->zeta > 0 && oil_column_resonance->zeta <= 2, where,
          "oil_column_resonance", "zeta", oil_column_resonance->zeta, "(0, 2]");
  }
  if (coulomb_friction) {
    Check(coulomb_friction->loss_mm >= 0 && coulomb_friction->loss_mm <= 10, where,
          "coulomb_friction", "loss_mm", coulomb_friction->loss_mm, "[0, 10] mm");
    Check(coulomb_friction->v_smooth_mm_s > 0 && coulomb_friction->v_smooth_mm_s <= 1000, where,
          "coulomb_friction", "v_smooth_mm_s", coulomb_friction->v_smooth_mm_s,
          "(0, 1000] mm/s");
  }
  if (backlash)
    Check(backlash->gap_mm >= 0 && backlash->gap_mm <= 10, where, "backlash", "gap_mm",
          backlash->gap_mm, "[0, 10] mm");
  if (servovalve_saturation)
    Check(servovalve_saturation->vmax_mm_per_s > 0 && servovalve_saturation->vmax_mm_per_s <= 1e9,
          where, "servovalve_saturation", "vmax_mm_per_s", servovalve_saturation->vmax_mm_per_s,
          "(0, 1e9] mm/s");
  if (sensor_noise) {
    Check(sensor_noise->rms_y_mm >= 0 && sensor_noise->rms_y_mm <= 10, where, "sensor_noise",
          "rms_y_mm", sensor_noise->rms_y_mm, "[0, 10] mm");
    Check(sensor_noise->rms_f_kN >= 0 && sensor_noise->rms_f_kN <= 100, where, "sensor_noise",
          "rms_f_kN", sensor_noise->rms_f_kN, "[0, 100] kN");
  }
  if (current_lag)
    Check(current_lag->tau_ms >= 0 && current_lag->tau_ms <= 1000, where, "current_lag",
          "tau_ms", current_lag->tau_ms, "[0, 1000] ms");
  if (damper_scale)
    Check(damper_scale->scale >= 0.1 && damper_scale->scale <= 10, where, "damper_scale",
          "scale", damper_scale->scale, "[0.1, 10]");
}

DisplacementEffects::DisplacementEffects(const EffectSet& effects, double dt_s)
    : e_(effects), dt_s_(dt_s) {
  if (!(dt_s > 0) || !std::isfinite(dt_s)) throw Error("DisplacementEffects", "dt_s must be > 0");
  e_.Validate(dt_s, "");
  if (e_.pure_delay) {
    const double d = e_.pure_delay->tau_ms * 1e-3 / dt_s;
    ring_.assign(static_cast<std::size_t>(std::floor(d)) + 2, 0.0);
  }
  if (e_.oil_column_resonance) {
    // q'' = w^2 (x - q) - 2 zeta w q': A = [0 1; -w^2 -2 zeta w], B = [0; w^2]; exact ZOH via
    // the exponential of the augmented matrix [A B; 0 0] dt.
    const double w = 2.0 * M_PI * e_.oil_column_resonance->f_hz;
    const double z = e_.oil_column_resonance->zeta;
    Eigen::Matrix3d aug = Eigen::Matrix3d::Zero();
    aug(0, 1) = 1.0;
    aug(1, 0) = -w * w;
    aug(1, 1) = -2.0 * z * w;
    aug(1, 2) = w * w;
    const Eigen::Matrix3d ex = (aug * dt_s).exp();
    a11_ = ex(0, 0); a12_ = ex(0, 1); a21_ = ex(1, 0); a22_ = ex(1, 1);
    b1_ = ex(0, 2); b2_ = ex(1, 2);
  }
  Reset();
}

void DisplacementEffects::Reset() {
  std::fill(ring_.begin(), ring_.end(), 0.0);
  head_ = 0;
  count_ = 0;
  q1_ = q2_ = 0.0;
  rate_out_ = 0.0;
  fric_prev_in_ = 0.0;
  play_out_ = 0.0;
}

bool DisplacementEffects::PreIsIdentity() const {
  return (!e_.pure_delay || e_.pure_delay->tau_ms == 0.0) &&
         (!e_.gain_error || e_.gain_error->gain == 1.0);
}

double DisplacementEffects::Pre(double u_mm) {
  double u = u_mm;
  if (e_.pure_delay) {
    // u_d,k = (1 - frac) u_{k-m} + frac u_{k-m-1}, d = tau / dt = m + frac; 0 before the start.
    const std::size_t n = ring_.size();
    head_ = (head_ + 1) % n;
    ring_[head_] = u_mm;
    count_ = std::min(count_ + 1, n);
    const double d = e_.pure_delay->tau_ms * 1e-3 / dt_s_;
    const std::size_t m = static_cast<std::size_t>(std::floor(d));
    const double frac = d - static_cast<double>(m);
    auto past = [&](std::size_t back) {
      return back < count_ ? ring_[(head_ + n - back) % n] : 0.0;
    };
    u = (1.0 - frac) * past(m) + (frac > 0.0 ? frac * past(m + 1) : 0.0);
  }
  if (e_.gain_error) u *= e_.gain_error->gain;
  return u;
}

double DisplacementEffects::Post(double x_mm, double f_kN) {
  double y = x_mm;
  if (e_.oil_column_resonance) {
    // The input x_k is held over the step that ends at t_k (a half-sample advance against a
    // continuous mode; the same in the rig and in the diagnosis).
    const double q1 = a11_ * q1_ + a12_ * q2_ + b1_ * y;
    const double q2 = a21_ * q1_ + a22_ * q2_ + b2_ * y;
    q1_ = q1;
    q2_ = q2;
    y = q1;
  }
  if (e_.servovalve_saturation) {
    const double dmax = e_.servovalve_saturation->vmax_mm_per_s * dt_s_;
    rate_out_ += std::clamp(y - rate_out_, -dmax, dmax);
    y = rate_out_;
  }
  if (e_.load_coupling) y -= e_.load_coupling->compliance_mm_per_kN * f_kN;
  if (e_.coulomb_friction) {
    const double v = (y - fric_prev_in_) / dt_s_;
    fric_prev_in_ = y;
    y -= e_.coulomb_friction->loss_mm * std::tanh(v / e_.coulomb_friction->v_smooth_mm_s);
  }
  if (e_.backlash) {
    const double h = 0.5 * e_.backlash->gap_mm;
    if (y - play_out_ > h) play_out_ = y - h;
    else if (y - play_out_ < -h) play_out_ = y + h;
    y = play_out_;
  }
  return y;
}

ForceEffects::ForceEffects(const EffectSet& effects, double dt_s) : e_(effects) {
  if (!(dt_s > 0) || !std::isfinite(dt_s)) throw Error("ForceEffects", "dt_s must be > 0");
  e_.Validate(dt_s, "");
  if (e_.current_lag && e_.current_lag->tau_ms > 0.0)
    a_ = std::exp(-dt_s / (e_.current_lag->tau_ms * 1e-3));
  Reset();
}

void ForceEffects::Reset(double i0_A) { lag_ = i0_A; }

double ForceEffects::Current(double i_A) {
  if (!e_.current_lag || a_ == 0.0) return i_A;
  lag_ = a_ * lag_ + (1.0 - a_) * i_A;
  return lag_;
}

double ForceEffects::Force(double f_kN) const {
  return e_.damper_scale ? e_.damper_scale->scale * f_kN : f_kN;
}

}  // namespace rths::models
