#include "models/rig_effects.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include <fmt/format.h>

#include "core/error.h"
#include "models/supply_ripple.h"

namespace rths::models {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A parameter's accessor: the field of the effect's struct, if the effect is on.
template <auto kEffect, auto kField>
double* FieldOf(EffectSet& set) {
  auto& effect = set.*kEffect;
  return effect ? &((*effect).*kField) : nullptr;
}
template <auto kEffect>
void TurnOn(EffectSet& set) {
  (set.*kEffect).emplace();
}
template <auto kEffect>
bool IsOn(const EffectSet& set) {
  return (set.*kEffect).has_value();
}

// key, valid [lo, hi], open ends, hi per dt, required | fitted, search [lo, hi], log, grid,
// search hi per dt, search hi from data | accessor
constexpr EffectParam kNoParam{};

}  // namespace

const std::array<EffectInfo, 15> kEffects = {{
    {"pure_delay", 'y', true,
     {{{"tau_ms", 0.0, 100.0, false, false, 0.0, true, true, 0.0, 40.0, false, 81, 0.0, false,
        FieldOf<&EffectSet::pure_delay, &PureDelay::tau_ms>},
       kNoParam}},
     1, TurnOn<&EffectSet::pure_delay>, IsOn<&EffectSet::pure_delay>},
    {"gain_error", 'y', true,
     {{{"gain", 0.5, 2.0, false, false, 0.0, true, true, 0.5, 2.0, true, 41, 0.0, false,
        FieldOf<&EffectSet::gain_error, &GainError::gain>},
       kNoParam}},
     1, TurnOn<&EffectSet::gain_error>, IsOn<&EffectSet::gain_error>},
    // The diagnosis searches c >= 0 only: an actuator yields under load.
    {"load_coupling", 'y', true,
     {{{"compliance_mm_per_kN", -1.0, 1.0, false, false, 0.0, true, true, 0.0, 0.2, false, 81, 0.0, false,
        FieldOf<&EffectSet::load_coupling, &LoadCoupling::compliance_mm_per_kN>},
       kNoParam}},
     1, TurnOn<&EffectSet::load_coupling>, IsOn<&EffectSet::load_coupling>},
    {"oil_column_resonance", 'y', true,
     {{{"f_hz", 0.0, kInf, true, true, 0.45, true, true, 2.0, 0.0, true, 40, 0.4, false,
        FieldOf<&EffectSet::oil_column_resonance, &OilColumnResonance::f_hz>},
       {"zeta", 0.0, 2.0, true, false, 0.0, false, true, 0.02, 1.5, true, 10, 0.0, false,
        FieldOf<&EffectSet::oil_column_resonance, &OilColumnResonance::zeta>}}},
     2, TurnOn<&EffectSet::oil_column_resonance>, IsOn<&EffectSet::oil_column_resonance>},
    {"coulomb_friction", 'y', true,
     {{{"loss_mm", 0.0, 10.0, false, false, 0.0, true, true, 1e-3, 10.0, true, 31, 0.0, false,
        FieldOf<&EffectSet::coulomb_friction, &CoulombFriction::loss_mm>},
       {"v_smooth_mm_s", 0.0, 1000.0, true, false, 0.0, false, false, 0.0, 0.0, false, 0, 0.0, false,
        FieldOf<&EffectSet::coulomb_friction, &CoulombFriction::v_smooth_mm_s>}}},
     2, TurnOn<&EffectSet::coulomb_friction>, IsOn<&EffectSet::coulomb_friction>},
    {"backlash", 'y', true,
     {{{"gap_mm", 0.0, 10.0, false, false, 0.0, true, true, 1e-3, 10.0, true, 31, 0.0, false,
        FieldOf<&EffectSet::backlash, &Backlash::gap_mm>},
       kNoParam}},
     1, TurnOn<&EffectSet::backlash>, IsOn<&EffectSet::backlash>},
    // in_loop: a switch (grid -1), the diagnosis fits vmax both ways and keeps the better.
    {"servovalve_saturation", 'y', true,
     {{{"vmax_mm_per_s", 0.0, 1e9, true, false, 0.0, true, true, 1.0, 0.0, true, 31, 0.0, true,
        FieldOf<&EffectSet::servovalve_saturation, &ServovalveSaturation::vmax_mm_per_s>},
       {"in_loop", 0.0, 1.0, false, false, 0.0, false, true, 0.0, 1.0, false, -1, 0.0, false,
        FieldOf<&EffectSet::servovalve_saturation, &ServovalveSaturation::in_loop>}}},
     2, TurnOn<&EffectSet::servovalve_saturation>, IsOn<&EffectSet::servovalve_saturation>},
    // The noise floor, not an effect the diagnosis selects; a table needs one of its keys.
    {"sensor_noise", 'b', false,
     {{{"rms_y_mm", 0.0, 10.0, false, false, 0.0, false, false, 0.0, 0.0, false, 0, 0.0, false,
        FieldOf<&EffectSet::sensor_noise, &SensorNoise::rms_y_mm>},
       {"rms_f_kN", 0.0, 100.0, false, false, 0.0, false, false, 0.0, 0.0, false, 0, 0.0, false,
        FieldOf<&EffectSet::sensor_noise, &SensorNoise::rms_f_kN>}}},
     2, TurnOn<&EffectSet::sensor_noise>, IsOn<&EffectSet::sensor_noise>},
    {"current_lag", 'f', true,
     {{{"tau_ms", 0.0, 1000.0, false, false, 0.0, true, true, 0.5, 1000.0, true, 12, 0.0, false,
        FieldOf<&EffectSet::current_lag, &CurrentLag::tau_ms>},
       kNoParam}},
     1, TurnOn<&EffectSet::current_lag>, IsOn<&EffectSet::current_lag>},
    // grid 0: fitted in closed form (least squares of the force's scale).
    {"damper_scale", 'f', true,
     {{{"scale", 0.1, 10.0, false, false, 0.0, true, true, 0.1, 10.0, true, 0, 0.0, false,
        FieldOf<&EffectSet::damper_scale, &DamperScale::scale>},
       kNoParam}},
     1, TurnOn<&EffectSet::damper_scale>, IsOn<&EffectSet::damper_scale>},
    // travel -> 0 is backlash: a fit that does not creep after a reversal is named backlash's
    // form by the diagnosis (diagnosis/candidates.h FormOf), not selected.
    {"presliding_friction", 'y', true,
     {{{"loss_mm", 0.0, 10.0, false, false, 0.0, true, true, 1e-3, 10.0, true, 21, 0.0, false,
        FieldOf<&EffectSet::presliding_friction, &PreslidingFriction::loss_mm>},
       {"travel_mm", 1e-6, 100.0, false, false, 0.0, false, true, 1e-3, 10.0, true, 13, 0.0, false,
        FieldOf<&EffectSet::presliding_friction, &PreslidingFriction::travel_mm>}}},
     2, TurnOn<&EffectSet::presliding_friction>, IsOn<&EffectSet::presliding_friction>},
    {"command_dead_band", 'y', true,
     {{{"width_mm", 0.0, 10.0, false, false, 0.0, true, true, 1e-3, 10.0, true, 31, 0.0, false,
        FieldOf<&EffectSet::command_dead_band, &CommandDeadBand::width_mm>},
       kNoParam}},
     1, TurnOn<&EffectSet::command_dead_band>, IsOn<&EffectSet::command_dead_band>},
    // grid 0: closed form (diagnosis/ripple_fit.h): the frequency from the residual's harmonic
    // spectrum, searched from 20 Hz (below, a periodic disturbance overlaps the tests' excitation
    // bands and is not a pump's piston frequency) to 0.45 / dt; the amplitude is the fundamental's,
    // fitted per record with the harmonics' phases and reported as their mean.
    {"supply_ripple", 'y', true,
     {{{"f_hz", 0.0, kInf, true, true, 0.5, true, true, 20.0, 0.0, true, 0, 0.45, false,
        FieldOf<&EffectSet::supply_ripple, &SupplyRipple::f_hz>},
       {"amplitude_mm", 0.0, 10.0, false, false, 0.0, true, true, 1e-6, 10.0, true, 0, 0.0, false,
        FieldOf<&EffectSet::supply_ripple, &SupplyRipple::amplitude_mm>}}},
     2, TurnOn<&EffectSet::supply_ripple>, IsOn<&EffectSet::supply_ripple>},
    // A DAQ's channel skew: from a fraction of a sample to a few ms; searched over +-10 ms (81
    // points, then golden section): beyond, the records' own pairing is wrong, not the DAQ's.
    {"channel_skew", 'f', true,
     {{{"skew_ms", -20.0, 20.0, false, false, 0.0, true, true, -10.0, 10.0, false, 81, 0.0, false,
        FieldOf<&EffectSet::channel_skew, &ChannelSkew::skew_ms>},
       kNoParam}},
     1, TurnOn<&EffectSet::channel_skew>, IsOn<&EffectSet::channel_skew>},
    // grid 0: closed form (least squares of the measured force on the modelled one and the
    // damper's smoothed acceleration, with damper_scale when both are in the set); searched in
    // [0.01, 1e4] kg on a log axis (a negative least-squares mass ends at 0.01: at a bound).
    {"load_cell_inertia", 'f', true,
     {{{"mass_kg", 0.0, 1e4, false, false, 0.0, true, true, 0.01, 1e4, true, 0, 0.0, false,
        FieldOf<&EffectSet::load_cell_inertia, &LoadCellInertia::mass_kg>},
       kNoParam}},
     1, TurnOn<&EffectSet::load_cell_inertia>, IsOn<&EffectSet::load_cell_inertia>},
}};

const EffectInfo* FindEffect(std::string_view name) {
  for (const EffectInfo& e : kEffects)
    if (e.name == name) return &e;
  return nullptr;
}

const EffectParam* EffectInfo::param(std::string_view key) const {
  for (const EffectParam& p : params())
    if (p.key == key) return &p;
  return nullptr;
}

bool EffectParam::Valid(double v, double dt_s) const {
  const double h = Hi(dt_s);
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < h : v <= h;
  return std::isfinite(v) && above && below;
}

std::string EffectParam::RangeText(double dt_s) const {
  std::string text = fmt::format("{}{}, {}{}", lo_open ? '(' : '[', lo, Hi(dt_s), hi_open ? ')' : ']');
  if (hi_per_dt > 0.0) text += fmt::format(" ({} / dt)", hi_per_dt);
  return text;
}

bool EffectSet::Empty() const {
  for (const EffectInfo& e : kEffects)
    if (e.is_on(*this)) return false;
  return true;
}

void EffectSet::Validate(double dt_s, std::string_view where) const {
  EffectSet copy = *this;  // the accessors give mutable fields
  for (const EffectInfo& e : kEffects) {
    for (const EffectParam& p : e.params()) {
      const double* v = p.field(copy);
      if (v == nullptr || (p.Valid(*v, dt_s) && (p.grid >= 0 || *v == 0.0 || *v == 1.0))) continue;
      if (p.grid < 0)
        throw Error(fmt::format("{}{}effects.{}.{}", where, where.empty() ? "" : ": ", e.name, p.key),
                    fmt::format("value {} is not allowed; allowed 0 or 1", *v));
      throw Error(fmt::format("{}{}effects.{}.{}", where, where.empty() ? "" : ": ", e.name, p.key),
                  fmt::format("value {} is out of range; allowed {}", *v, p.RangeText(dt_s)));
    }
  }
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
  dahl_prev_in_ = 0.0;
  dahl_z_ = 0.0;
  x_last_ = 0.0;
  post_k_ = 0;
}

bool DisplacementEffects::PreIsIdentity() const {
  return (!e_.pure_delay || e_.pure_delay->tau_ms == 0.0) &&
         (!e_.gain_error || e_.gain_error->gain == 1.0) &&
         (!e_.command_dead_band || e_.command_dead_band->width_mm == 0.0);
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
  if (e_.command_dead_band) {
    const double h = 0.5 * e_.command_dead_band->width_mm;
    const double e = u - x_last_;
    u = x_last_ + (e > h ? e - h : e < -h ? e + h : 0.0);
  }
  return u;
}

double DisplacementEffects::Post(double x_mm, double f_kN) {
  x_last_ = x_mm;
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
  if (e_.servovalve_saturation && !e_.servovalve_saturation->InLoop()) {  // in the loop: the actuator model's
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
  if (e_.presliding_friction) y -= PreslidingStep(y);
  if (e_.backlash) {
    const double h = 0.5 * e_.backlash->gap_mm;
    if (y - play_out_ > h) play_out_ = y - h;
    else if (y - play_out_ < -h) play_out_ = y + h;
    y = play_out_;
  }
  if (e_.supply_ripple) y += SupplyRippleAt(*e_.supply_ripple, dt_s_, static_cast<double>(post_k_) * dt_s_).mm;
  ++post_k_;
  return y;
}

double DisplacementEffects::PreslidingStep(double x_mm) {
  // With s = sgn(dx) and w = loss - s z in [0, 2 loss] (0: sliding, 2 loss: just reversed),
  // dz/dy = s w / travel and dy = dx - dz give dw/d|x| = -w / (travel + w), whose solution over a
  // travel |dx| is travel ln w + w = travel ln w_prev + w_prev - |dx|: w = travel W(e^q),
  // q = ln(w_prev / travel) + (w_prev - |dx|) / travel, W + ln W = q solved by Newton in ln W
  // (convex and increasing: from ln(w_prev / travel), above the root, it converges monotonically).
  const double loss = e_.presliding_friction->loss_mm, travel = e_.presliding_friction->travel_mm;
  const double dx = x_mm - dahl_prev_in_;
  dahl_prev_in_ = x_mm;
  if (dx == 0.0 || loss == 0.0) return dahl_z_;
  const double s = dx > 0.0 ? 1.0 : -1.0;
  const double w_prev = std::clamp(loss - s * dahl_z_, 0.0, 2.0 * loss);
  if (w_prev <= 1e-12 * loss) {  // already sliding this way: the lost motion stays at s loss
    dahl_z_ = s * loss;
    return dahl_z_;
  }
  const double l0 = std::log(w_prev) - std::log(travel);
  const double q = l0 + (w_prev - std::abs(dx)) / travel;
  double l = l0;
  for (int it = 0; it < 60; ++it) {
    const double el = std::exp(l);
    const double step = (el + l - q) / (el + 1.0);
    l -= step;
    if (std::abs(step) < 1e-13 * (1.0 + std::abs(l))) break;
  }
  const double w = std::clamp(travel * std::exp(l), 0.0, w_prev);
  dahl_z_ = s * (loss - w);
  return dahl_z_;
}

RippleMotion SupplyRippleAt(const SupplyRipple& r, double dt_s, double t_s) {
  RippleMotion m;
  for (int h = 0; h < kRippleHarmonics; ++h) {
    if (!RippleHarmonicSampled(h + 1, r.f_hz, dt_s)) continue;
    const double w = 2.0 * M_PI * (h + 1) * r.f_hz, a = r.amplitude_mm * kRippleWeights[h];
    m.mm += a * std::sin(w * t_s + kRipplePhases[h]);
    m.mm_s += a * w * std::cos(w * t_s + kRipplePhases[h]);
  }
  return m;
}

double ShiftedSample(std::span<const double> x, double pos) {
  const auto n = static_cast<std::ptrdiff_t>(x.size());
  if (n == 0) return 0.0;
  const double fl = std::floor(pos);
  const auto j = static_cast<std::ptrdiff_t>(fl);
  const double t = pos - fl;  // in [0, 1)
  auto at = [&](std::ptrdiff_t i) { return x[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(i, 0, n - 1))]; };
  if (t == 0.0) return at(j);
  // Lagrange weights on the nodes -1, 0, 1, 2 at t.
  const double wm = -t * (t - 1.0) * (t - 2.0) / 6.0;
  const double w0 = (t + 1.0) * (t - 1.0) * (t - 2.0) / 2.0;
  const double w1 = -(t + 1.0) * t * (t - 2.0) / 2.0;
  const double w2 = (t + 1.0) * t * (t - 1.0) / 6.0;
  return wm * at(j - 1) + w0 * at(j) + w1 * at(j + 1) + w2 * at(j + 2);
}

std::vector<double> ShiftSamples(std::span<const double> x, double skew_s, double dt_s) {
  std::vector<double> y(x.begin(), x.end());
  if (skew_s == 0.0) return y;
  const double d = skew_s / dt_s;
  for (std::size_t k = 0; k < y.size(); ++k) y[k] = ShiftedSample(x, static_cast<double>(k) - d);
  return y;
}

MeasurementEffects::MeasurementEffects(const EffectSet& effects, double dt_s) {
  if (!(dt_s > 0) || !std::isfinite(dt_s)) throw Error("MeasurementEffects", "dt_s must be > 0");
  effects.Validate(dt_s, "");
  if (effects.load_cell_inertia) mass_kg_ = effects.load_cell_inertia->mass_kg;
  if (effects.channel_skew && effects.channel_skew->skew_ms != 0.0) {
    const double skew_s = 1e-3 * effects.channel_skew->skew_ms;
    delay_force_ = skew_s > 0.0;
    delay_samples_ = std::abs(skew_s) / dt_s;
    line_.assign(static_cast<std::size_t>(std::floor(delay_samples_)) + 4, 0.0);
  }
  Reset();
}

void MeasurementEffects::Reset() {
  std::fill(line_.begin(), line_.end(), 0.0);
  head_ = 0;
  count_ = 0;
}

double MeasurementEffects::Delay(double v) {
  const std::size_t n = line_.size();
  head_ = (head_ + 1) % n;
  line_[head_] = v;
  count_ = std::min(count_ + 1, n);
  // back(b): the value b samples ago (b = 0: v); before the line filled, the oldest one.
  auto back = [&](std::size_t b) { return line_[(head_ + n - std::min(b, count_ - 1)) % n]; };
  // The newest four samples that bracket t_k - d: nodes b0 + 2 .. b0 - 1 samples ago with
  // b0 = max(floor(d), 1) - 1 ... i.e. the interval [floor(d), floor(d) + 1] ago, centred when
  // the line allows, else shifted towards the present (d < 1).
  const double fl = std::floor(delay_samples_);
  const double t = delay_samples_ - fl;  // fraction of a sample beyond floor(d) ago
  const auto m = static_cast<std::size_t>(fl);
  if (t == 0.0) return back(m);
  // Nodes at m - 1, m, m + 1, m + 2 samples ago (position -(m + t) between m and m + 1 ago); for
  // m = 0 the node 'm - 1 ago' is in the future: use m .. m + 3 ago instead.
  const std::size_t b0 = m == 0 ? 0 : m - 1;
  const double pos = static_cast<double>(m) + t - static_cast<double>(b0);  // in samples ago from b0
  // Lagrange on nodes 0, 1, 2, 3 (samples ago from b0) at pos.
  const double l0 = -(pos - 1.0) * (pos - 2.0) * (pos - 3.0) / 6.0;
  const double l1 = pos * (pos - 2.0) * (pos - 3.0) / 2.0;
  const double l2 = -pos * (pos - 1.0) * (pos - 3.0) / 2.0;
  const double l3 = pos * (pos - 1.0) * (pos - 2.0) / 6.0;
  return l0 * back(b0) + l1 * back(b0 + 1) + l2 * back(b0 + 2) + l3 * back(b0 + 3);
}

void MeasurementEffects::Measure(double y_mm, double a_mm_s2, double f_kN, double* y_meas_mm, double* f_meas_kN) {
  double f = f_kN + 1e-6 * mass_kg_ * a_mm_s2;
  double y = y_mm;
  if (!line_.empty()) {
    if (delay_force_) f = Delay(f);
    else y = Delay(y);
  }
  *y_meas_mm = y;
  *f_meas_kN = f;
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
