#include "validation/synthetic.h"

#include <algorithm>

#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "models/coupling_solver.h"
#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/rig.h"
#include "models/servo_flow_limit.h"
#include "models/servo_linear.h"
#include "models/supply_ripple.h"
#include "signal/blwn.h"
#include "signal/random.h"

namespace rths::validation {

void MakeInputs(const Excitation& ex, std::vector<double>* u_mm, std::vector<double>* i_A) {
  const auto n = static_cast<std::size_t>(std::lround(ex.duration_s / ex.dt_s));
  *u_mm = signal::Blwn(ex.band_hz, ex.rms_mm, ex.dt_s, n, ex.seed, 2.0);
  // Fade in over 0.25 s so that the record starts at rest.
  const auto nf = static_cast<std::size_t>(std::lround(0.25 / ex.dt_s));
  for (std::size_t k = 0; k < std::min(n, nf); ++k) (*u_mm)[k] *= 0.5 * (1.0 - std::cos(M_PI * k / nf));
  i_A->assign(n, ex.current_max_A);
  if (ex.current_constant) return;
  auto g = signal::MakeGaussian(ex.seed * 7919 + 17);
  std::size_t k = 0;
  while (k < n) {
    const int level = static_cast<int>(std::floor(6.0 * signal::NextUniform(&g)));
    const double hold = ex.hold_min_s + (ex.hold_max_s - ex.hold_min_s) * signal::NextUniform(&g);
    const std::size_t m = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(hold / ex.dt_s)));
    const double i_level = k == 0 && ex.current_start_A >= 0.0 ? ex.current_start_A : ex.current_max_A * std::min(level, 5) / 5.0;
    for (std::size_t j = k; j < std::min(n, k + m); ++j) (*i_A)[j] = i_level;
    k += m;
  }
}

namespace {

/// The driver's state one step on (a copy).
models::CurrentDriverState Advanced(const models::CurrentDriver& driver, models::CurrentDriverState cs) {
  models::Advance(driver, &cs);
  return cs;
}

io::RigRecord Empty(const Excitation& ex, const std::string& name, std::size_t n) {
  io::RigRecord r;
  r.dt_s = ex.dt_s;
  r.source = name;
  r.t_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) r.t_s[k] = static_cast<double>(k) * ex.dt_s;
  r.y_mm.resize(n);
  r.f_kN.resize(n);
  return r;
}

/// What the output effects add to the specimen's motion over the step from sample k - 1 (d_prev =
/// y - x there) to k (d_end), as the rig mode moves its damper: linear between the samples, except
/// supply_ripple's share, its continuous motion (models/supply_ripple.h; Post gives sample k its
/// ripple at k dt).
class EffectShare {
 public:
  EffectShare(const models::EffectSet& e, double dt, std::size_t k, double d_prev, double d_end)
      : ripple_(e.supply_ripple ? &*e.supply_ripple : nullptr), dt_(dt),
        t_prev_((static_cast<double>(k) - 1.0) * dt) {
    end_ = Ripple(static_cast<double>(k) * dt);
    d0_ = d_prev - (k > 0 ? Ripple(t_prev_).mm : 0.0);
    dd_ = k > 0 ? (d_end - end_.mm - d0_) / dt : 0.0;
  }
  /// Adds the share at tau [s] into the step to *pos [mm] and *vel [mm/s].
  void Add(double tau, double* pos, double* vel) const {
    const models::RippleMotion r = Ripple(t_prev_ + tau);
    *pos += d0_ + dd_ * tau + r.mm;
    *vel += dd_ + r.mm_s;
  }
  /// Its rate at sample k [mm/s].
  double EndRate() const { return dd_ + end_.mm_s; }

 private:
  models::RippleMotion Ripple(double t) const {
    return ripple_ ? models::SupplyRippleAt(*ripple_, dt_, t) : models::RippleMotion{};
  }
  const models::SupplyRipple* ripple_;
  double dt_, t_prev_, d0_ = 0.0, dd_ = 0.0;
  models::RippleMotion end_;
};

}  // namespace

io::RigRecord MakeRecordBlocks(const Excitation& ex, const Truth& truth, const std::string& name) {
  std::vector<double> u, i;
  MakeInputs(ex, &u, &i);
  const std::size_t n = u.size();
  io::RigRecord r = Empty(ex, name, n);
  r.u_mm = u;
  r.i_A = i;
  const double dt = ex.dt_s;
  const auto servo = models::LinearServo::Make(models::ServoPreset("avg"), dt);
  models::LinearServoState xs;
  // servovalve_saturation in the loop: the flow-limited actuator instead (models/servo_flow_limit.h).
  std::optional<models::FlowLimitedServo> limited;
  if (truth.effects.servovalve_saturation && truth.effects.servovalve_saturation->InLoop())
    limited = models::FlowLimitedServo::Make(servo, truth.effects.servovalve_saturation->vmax_mm_per_s);
  models::FlowLimitedServoState ls;
  models::DisplacementEffects dfx(truth.effects, dt);
  models::ForceEffects ffx(truth.effects, dt);
  const double i_before = truth.driver_at_rest ? 0.0 : i[0];  // what the driver held before the record
  ffx.Reset(i_before);
  const auto driver = models::CurrentDriver::Make({}, dt);
  models::CurrentDriverState cs = models::SteadyState(i_before);
  const auto damper = models::MrDamperParams::Table3();
  models::MrDamperState ds{};
  auto g = signal::MakeGaussian(truth.noise_seed);
  const double sy = truth.effects.sensor_noise ? truth.effects.sensor_noise->rms_y_mm : 0.0;
  const double sf = truth.effects.sensor_noise ? truth.effects.sensor_noise->rms_f_kN : 0.0;
  // The damper's motion inside a step, as in the rig mode (models/effect_rig.h): the servo's
  // continuous motion (cubic Hermite through its samples x_k with its velocities C A z_k, exact
  // for a cubic, close for the servo) plus a linear interpolation of what the effects add,
  // d_k = y_k - x_k.
  // load_coupling sees the force of the same sample, as in the rig mode: a fixed point solved
  // by models::SolveCoupledForce, each trial re-integrating the step from the saved state.
  double x_prev = 0.0, xd_prev = 0.0, d_prev = 0.0, d_prev2 = 0.0, f_prev = 0.0, f_prev2 = 0.0;
  // The load cell's force before noise (load_cell_inertia added), shifted by channel_skew after the loop.
  std::vector<double> f_cell(n, 0.0);
  models::DisplacementEffects dfx_try = dfx;  // a trial's copy: same sizes, assigned without allocating
  for (std::size_t k = 0; k < n; ++k) {
    const double x = limited ? ls.x : models::Output(servo, xs);
    const double xd = limited ? models::Velocity(*limited, ls) : models::OutputVelocity(servo, xs);
    // One trial: the output effects and the damper from the step's start, fed the force f_in.
    models::MrDamperState ds_try = ds;
    double y = 0.0, f = 0.0;
    auto trial = [&](double f_in) {
      dfx_try = dfx;
      ds_try = ds;
      y = dfx_try.Post(x, f_in);
      const EffectShare share(truth.effects, dt, k, d_prev, y - x);
      const double v = xd + share.EndRate();
      if (k > 0) {
        const int m = 8;
        const double h = dt / m;
        auto at = [&](double tau, double* pos, double* vel) {
          const double t = tau / dt, t2 = t * t, t3 = t2 * t;
          *pos = (2 * t3 - 3 * t2 + 1) * x_prev + (t3 - 2 * t2 + t) * dt * xd_prev + (-2 * t3 + 3 * t2) * x +
                 (t3 - t2) * dt * xd;
          *vel = ((6 * t2 - 6 * t) * x_prev + (3 * t2 - 4 * t + 1) * dt * xd_prev + (-6 * t2 + 6 * t) * x +
                  (3 * t2 - 2 * t) * dt * xd) / dt;
          share.Add(tau, pos, vel);
        };
        for (int j = 0; j < m; ++j) {
          const double ta = j * h;
          auto coef = [&](double tau) { return models::CoefficientsAt(damper, models::EffectiveCurrentAt(driver, cs, tau)); };
          const auto ca = coef(ta), cb = coef(ta + 0.5 * h), cc = coef(ta + h);
          double pa, va, pb, vb, pc, vc;
          at(ta, &pa, &va);
          at(ta + 0.5 * h, &pb, &vb);
          at(ta + h, &pc, &vc);
          const auto r1 = models::DamperRates(ca, ds_try, pa, va);
          const models::MrDamperState s2{ds_try.y_mm + 0.5 * h * r1.ydot_mm_s, ds_try.z_mm + 0.5 * h * r1.zdot_mm_s};
          const auto r2 = models::DamperRates(cb, s2, pb, vb);
          const models::MrDamperState s3{ds_try.y_mm + 0.5 * h * r2.ydot_mm_s, ds_try.z_mm + 0.5 * h * r2.zdot_mm_s};
          const auto r3 = models::DamperRates(cb, s3, pb, vb);
          const models::MrDamperState s4{ds_try.y_mm + h * r3.ydot_mm_s, ds_try.z_mm + h * r3.zdot_mm_s};
          const auto r4 = models::DamperRates(cc, s4, pc, vc);
          ds_try.y_mm += h / 6.0 * (r1.ydot_mm_s + 2 * r2.ydot_mm_s + 2 * r3.ydot_mm_s + r4.ydot_mm_s);
          ds_try.z_mm += h / 6.0 * (r1.zdot_mm_s + 2 * r2.zdot_mm_s + 2 * r3.zdot_mm_s + r4.zdot_mm_s);
        }
      }
      const double ic = models::EffectiveCurrentA(driver, k > 0 ? Advanced(driver, cs) : cs);
      f = ffx.Force(models::DamperForceKn(models::CoefficientsAt(damper, ic), ds_try, y, v));
      f *= std::clamp(truth.fade_start + truth.fade_per_s * static_cast<double>(k) * dt, 0.05, 10.0);
      f += truth.stiffness_kN_per_mm * y;
      return f - f_in;
    };
    if (truth.effects.load_coupling) {
      const double f_start = k >= 2 ? 2.0 * f_prev - f_prev2 : f_prev;
      const auto solved = models::SolveCoupledForce(trial, f_start, truth.effects.load_coupling->compliance_mm_per_kN, 20);
      if (!std::isfinite(f)) throw Error(name, fmt::format("load_coupling: the force of sample {} is not finite", k));
      (void)solved;  // unconverged (a sticking seal): the closest trial, as the rig mode takes it
    } else {
      trial(f_prev);
    }
    std::swap(dfx, dfx_try);  // the accepted trial's state
    ds = ds_try;
    if (k > 0) models::Advance(driver, &cs);
    const double d = y - x;
    const double t = static_cast<double>(k) * dt;
    r.y_mm[k] = y + truth.ripple_mm * std::sin(2.0 * M_PI * truth.ripple_hz * t) + sy * signal::NextGaussian(&g);
    r.f_kN[k] = sf * signal::NextGaussian(&g);  // the force is added below
    // load_cell_inertia: the specimen's acceleration, the servo's exact y'' plus the second
    // difference of the effects' share (as the rig mode takes it).
    const double acc = (limited ? models::Acceleration(*limited, ls) : xs.z(2)) +
                       (k >= 2 ? (d - 2.0 * d_prev + d_prev2) / (dt * dt) : 0.0);
    f_cell[k] = f + (truth.effects.load_cell_inertia ? 1e-6 * truth.effects.load_cell_inertia->mass_kg * acc : 0.0);
    d_prev2 = d_prev;
    // Step k -> k+1.
    models::Hold(driver, &cs, ffx.Current(i[k]));
    if (limited) models::Step(*limited, &ls, dfx.Pre(u[k]));
    else models::Step(servo, &xs, dfx.Pre(u[k]));
    x_prev = x, xd_prev = xd, d_prev = d, f_prev2 = f_prev, f_prev = f;
  }
  // channel_skew: the force channel records the load cell's force at t_k - skew (offline: either sign).
  const double skew_s = truth.effects.channel_skew ? 1e-3 * truth.effects.channel_skew->skew_ms : 0.0;
  const std::vector<double> f_rec = models::ShiftSamples(f_cell, skew_s, dt);
  for (std::size_t k = 0; k < n; ++k) r.f_kN[k] += f_rec[k];
  r.metadata.push_back({"generator", "validation::MakeRecordBlocks"});
  io::ValidateRigRecord(r, name);
  return r;
}

io::RigRecord MakeRecordRig(const Excitation& ex, const Truth& truth, const std::string& name) {
  std::vector<double> u, i;
  MakeInputs(ex, &u, &i);
  const std::size_t n = u.size();
  models::PlantConfig plant;
  plant.kind = models::PlantKind::kLinear;
  plant.actuator = models::ServoPreset("avg");
  plant.specimen = models::Specimen::kMrDamper;
  plant.current_dynamics = true;
  if (truth.driver_at_rest) plant.current_driver.start = models::CurrentStart::kRest;
  plant.effects = truth.effects;
  plant.noise_seed = truth.noise_seed;
  plant.unmodelled.ripple_mm = truth.ripple_mm;
  plant.unmodelled.ripple_hz = truth.ripple_mm > 0 ? truth.ripple_hz : 0.0;
  plant.unmodelled.stiffness_kN_per_mm = truth.stiffness_kN_per_mm;
  plant.unmodelled.fade_start = truth.fade_start;
  plant.unmodelled.fade_per_s = truth.fade_per_s;
  auto rig = models::MakeRig(plant, ex.dt_s);
  io::RigRecord r = Empty(ex, name, n);
  r.u_mm = u;
  r.i_A = i;
  for (std::size_t k = 0; k < n; ++k) {
    r.y_mm[k] = rig->y_mm();
    r.f_kN[k] = rig->f_kN();
    rig->Step(u[k], i[k]);
  }
  r.metadata.push_back({"generator", "models::MakeRig (rig mode)"});
  io::ValidateRigRecord(r, name);
  return r;
}

}  // namespace rths::validation
