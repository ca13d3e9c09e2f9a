#include "models/effect_rig.h"
#include "models/supply_ripple.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "models/coupling_solver.h"

namespace rths::models {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Absolute tolerances as the linear rig's (linear_rig.cpp): rtol x 0.01 mm for displacements,
// scaled by the servo's pole size w = d0^(1/3) [1/s] for its velocity and acceleration states.
std::array<double, 5> AbsTol(const LinearRig& rig) {
  const double w = std::cbrt(-rig.servo.A(2, 0));
  const double a = rig.rtol * 0.01;
  return {a, a * w, a * w * w, a, a};
}

}  // namespace

std::uint64_t EffectNoiseSeed(std::uint64_t noise_seed) {
  std::uint64_t z = noise_seed + 0x9E3779B97F4A7C15ULL;  // SplitMix64
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

EffectRigModel EffectRigModel::Make(const models::PlantConfig& plant, double dt_s) {
  if (plant.kind != PlantKind::kLinear) {
    throw Error("plant.kind", fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act "
                                          "around the linear actuator model",
                                          NameOf(kPlantKindNames, plant.kind)));
  }
  const bool damper = HasDamper(plant);
  plant.effects.Validate(dt_s, "plant");
  const auto& u = plant.unmodelled;
  if (!(std::isfinite(u.ripple_mm) && u.ripple_mm >= 0.0 && u.ripple_mm <= 10.0))
    throw Error("plant.unmodelled.ripple_mm", fmt::format("{} is out of range [0, 10]", u.ripple_mm));
  if (u.ripple_mm > 0.0 && !(u.ripple_hz > 0.0 && u.ripple_hz < 0.5 / dt_s))
    throw Error("plant.unmodelled.ripple_hz",
                fmt::format("{} is out of range (0, {}) (below the Nyquist frequency)", u.ripple_hz, 0.5 / dt_s));
  if (!(std::isfinite(u.stiffness_kN_per_mm) && std::abs(u.stiffness_kN_per_mm) <= 100.0))
    throw Error("plant.unmodelled.stiffness_kN_per_mm",
                fmt::format("{} is out of range [-100, 100]", u.stiffness_kN_per_mm));
  if (!(std::isfinite(u.fade_start) && u.fade_start >= 0.1 && u.fade_start <= 10.0))
    throw Error("plant.unmodelled.fade_start", fmt::format("{} is out of range [0.1, 10]", u.fade_start));
  if (!(std::isfinite(u.fade_per_s) && std::abs(u.fade_per_s) <= 1.0))
    throw Error("plant.unmodelled.fade_per_s", fmt::format("{} is out of range [-1, 1]", u.fade_per_s));
  EffectRigModel m;
  m.rig = LinearRig::Make(plant.actuator, dt_s, damper, plant.damper, plant.ode_rtol, plant.current_dynamics,
                          plant.current_driver);
  m.effects = plant.effects;
  m.unmodelled = plant.unmodelled;
  m.noise_seed = plant.noise_seed;
  m.coupling_same_sample = plant.load_coupling_same_sample;
  return m;
}

EffectRig::EffectRig(const EffectRigModel& model)
    : m_(model),
      disp_(model.effects, model.rig.servo.dt_s),
      force_(model.effects, model.rig.servo.dt_s),
      meas_(model.effects, model.rig.servo.dt_s),
      scratch_(disp_),
      noise_(signal::MakeGaussian(EffectNoiseSeed(model.noise_seed))),
      ode_(5, model.rig.rtol, AbsTol(model.rig), &EffectRig::Rhs, this) {
  m_.rig.damper.Validate();
  if (m_.effects.servovalve_saturation && m_.effects.servovalve_saturation->InLoop())
    limited_ = FlowLimitedServo::Make(m_.rig.servo, m_.effects.servovalve_saturation->vmax_mm_per_s);
  // Sample 0: at rest, 0 A (as the linear rig).
  f_ = m_.rig.has_damper ? force_.Force(DamperForceKn(CoefficientsAt(m_.rig.damper, 0.0), damper_, 0.0, 0.0))
                         : 0.0;
  Measure();
}

int EffectRig::Rhs(double t, const double* w, double* wdot, void* self) {
  const auto* me = static_cast<const EffectRig*>(self);
  const LinearServo& servo = me->m_.rig.servo;
  double x = 0.0, xdot = 0.0;
  if (me->limited_) {  // [x, xv, w] of the flow-limited servo (its derivative in [w, x, xv] order)
    const double st[3] = {w[2], w[0], w[1]};
    double d[3];
    Derivative(*me->limited_, st, me->u_act_, d);
    wdot[0] = d[1], wdot[1] = d[2], wdot[2] = d[0];
    x = w[0], xdot = d[1];
  } else {
    const Eigen::Map<const Eigen::Vector3d> z(w);
    const Eigen::Vector3d zdot = servo.A * z + servo.B * me->u_act_;
    wdot[0] = zdot(0), wdot[1] = zdot(1), wdot[2] = zdot(2);
    x = (servo.C * z).value(), xdot = (servo.C * zdot).value();
  }
  // Specimen motion: the servo's x(t) plus the effects' offset, linear over the step.
  double y = x + (me->d0_ + me->dv_ * t);
  double ydot = xdot + me->dv_;
  if (me->ripple_in_step_) {  // supply_ripple: its continuous motion, not a line between samples
    const RippleMotion r = SupplyRippleAt(*me->m_.effects.supply_ripple, servo.dt_s, me->ripple_t0_s_ + t);
    y += r.mm, ydot += r.mm_s;
  }
  const MrDamperCoefficients coef =
      me->constant_current_
          ? me->coef_
          : CoefficientsAt(me->m_.rig.damper, EffectiveCurrentAt(me->m_.rig.driver, me->current_, t));
  const MrDamperRates r = DamperRates(coef, {w[3], w[4]}, y, ydot);
  wdot[3] = r.ydot_mm_s;
  wdot[4] = r.zdot_mm_s;
  return 0;
}

double EffectRig::Trial(double x0, double x1, double x1_dot, double y1, double i_end_A, MrDamperState* damper) {
  const LinearRig& rig = m_.rig;
  // supply_ripple: Post gave sample j its ripple at (j - 1) dt (sample 0, at rest, has none); from
  // the second step on the damper moves with the ripple itself (Rhs), the rest of the effects'
  // share stays linear over the step.
  ripple_in_step_ = m_.effects.supply_ripple.has_value() && k_ >= 1;
  RippleMotion r0, r1;
  if (ripple_in_step_) {
    ripple_t0_s_ = static_cast<double>(k_ - 1) * rig.servo.dt_s;
    r0 = SupplyRippleAt(*m_.effects.supply_ripple, rig.servo.dt_s, ripple_t0_s_);
    r1 = SupplyRippleAt(*m_.effects.supply_ripple, rig.servo.dt_s, ripple_t0_s_ + rig.servo.dt_s);
  }
  d0_ = y_ - x0 - r0.mm;
  dv_ = ((y1 - x1 - r1.mm) - d0_) / rig.servo.dt_s;
  *damper = damper_;
  double force = 0.0;
  if (rig.has_damper) {
    double w[5] = {servo_.z(0), servo_.z(1), servo_.z(2), damper_.y_mm, damper_.z_mm};
    if (limited_) w[0] = loop_.x, w[1] = loop_.xv, w[2] = loop_.w;
    ode_.Advance(0.0, rig.servo.dt_s, w);
    *damper = {w[3], w[4]};
    const double ydot = x1_dot + dv_ + r1.mm_s;
    force = DamperForceKn(CoefficientsAt(rig.damper, i_end_A), *damper, y1, ydot);
  }
  // The fading damper (outside the library) at t_{k+1}, bounded so that a long run cannot reverse it.
  const double fade = std::clamp(m_.unmodelled.FadeAt(static_cast<double>(k_ + 1) * rig.servo.dt_s), 0.05, 10.0);
  return fade * force_.Force(force) + m_.unmodelled.stiffness_kN_per_mm * y1;
}

void EffectRig::Step(double u_mm, double i_cmd_A) {
  const LinearRig& rig = m_.rig;
  if (k_ == 0) {  // [plant.current_driver] start: every lag at the first command's steady state, or at rest
    const bool rest = rig.driver.params.start == CurrentStart::kRest;
    force_.Reset(rest ? 0.0 : i_cmd_A);
    current_ = StartState(rig.driver.params, i_cmd_A);
  }
  // Force path, current: the extra lag, then the model's own current dynamics.
  const double i_lag = force_.Current(i_cmd_A);
  if (rig.current_dynamics) {
    Hold(rig.driver, &current_, i_lag);
  } else {
    current_ = SteadyState(i_lag);
  }
  constant_current_ = AtSteadyState(current_);
  if (rig.has_damper && constant_current_) coef_ = CoefficientsAt(rig.damper, current_.held_A);
  CurrentDriverState end = current_;
  if (rig.current_dynamics) Advance(rig.driver, &end);
  const double i_end = EffectiveCurrentA(rig.driver, end);

  // Displacement path: command effects, the servo (exact ZOH), output effects.
  u_act_ = disp_.Pre(u_mm);
  const double x0 = actuator_x_mm();
  LinearServoState next = servo_;
  FlowLimitedServoState loop_next = loop_;
  if (limited_) models::Step(*limited_, &loop_next, u_act_);
  else models::Step(rig.servo, &next, u_act_);
  const double x1 = limited_ ? loop_next.x : Output(rig.servo, next);
  const double x1_dot = limited_ ? Velocity(*limited_, loop_next) : OutputVelocity(rig.servo, next);

  double y1 = 0.0, f1 = 0.0;
  MrDamperState damper{};
  if (!m_.effects.load_coupling || !m_.coupling_same_sample) {
    y1 = disp_.Post(x1, f_);
    f1 = Trial(x0, x1, x1_dot, y1, i_end, &damper);
  } else {
    // Load coupling: y_{k+1} = Post(x_{k+1}, f_{k+1}) with the force of the same sample
    // (models/coupling_solver.h).
    auto eval = [&](double f_in) {
      scratch_ = disp_;  // same sizes: no allocation
      y1 = scratch_.Post(x1, f_in);
      f1 = Trial(x0, x1, x1_dot, y1, i_end, &damper);
      return f1 - f_in;
    };
    const double f_start = k_ >= 1 ? 2.0 * f_ - f_prev_ : f_;  // linear extrapolation of the force
    f_prev_ = f_;
    const CoupledForce solved =
        SolveCoupledForce(eval, f_start, m_.effects.load_coupling->compliance_mm_per_kN, kMaxCouplingIterations);
    if (!std::isfinite(f1)) {
      throw Error("EffectRig: load_coupling", fmt::format("the force of step {} is not finite", k_ + 1));
    }
    if (!solved.converged) ++unconverged_steps_;
    std::swap(disp_, scratch_);  // the state of the accepted evaluation (swap: no allocation)
  }
  damper_ = damper;
  servo_ = next;  // authoritative for x (exact ZOH)
  loop_ = loop_next;
  current_ = end;
  y_ = y1;
  f_ = f1;
  ++k_;
  Measure();
}

void EffectRig::Measure() {
  // The specimen's acceleration at t_k: the servo's own y'' (exact) plus the second backward
  // difference of what the displacement effects add to it (load_cell_inertia only).
  const double dt = m_.rig.servo.dt_s;
  const double d = y_ - actuator_x_mm();
  const double a = (limited_ ? Acceleration(*limited_, loop_) : servo_.z(2)) +
                   (k_ >= 2 ? (d - 2.0 * d_prev_ + d_prev2_) / (dt * dt) : 0.0);
  d_prev2_ = d_prev_;
  d_prev_ = d;
  double y = 0.0, f = 0.0;
  meas_.Measure(y_, a, f_, &y, &f);
  if (m_.unmodelled.ripple_mm > 0.0) {
    const double t = static_cast<double>(k_) * m_.rig.servo.dt_s;
    y += m_.unmodelled.ripple_mm * std::sin(kTwoPi * m_.unmodelled.ripple_hz * t);
  }
  if (m_.effects.sensor_noise) {
    if (m_.effects.sensor_noise->rms_y_mm > 0.0) y += m_.effects.sensor_noise->rms_y_mm * signal::NextGaussian(&noise_);
    if (m_.effects.sensor_noise->rms_f_kN > 0.0) f += m_.effects.sensor_noise->rms_f_kN * signal::NextGaussian(&noise_);
  }
  y_meas_ = y;
  f_meas_ = f;
}

std::unique_ptr<Rig> MakeEffectRig(const models::PlantConfig& plant, double dt_s) {
  return std::make_unique<EffectRig>(EffectRigModel::Make(plant, dt_s));
}

}  // namespace rths::models
