#include "models/effect_rig.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

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

EffectRigModel EffectRigModel::Make(const scenario::PlantConfig& plant, double dt_s) {
  if (plant.kind != "linear") {
    throw Error("plant.kind", fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act "
                                          "around the linear actuator model",
                                          plant.kind));
  }
  bool damper = false;
  if (plant.specimen == "mr_damper") {
    damper = true;
  } else if (plant.specimen != "none") {
    throw Error("plant.specimen",
                fmt::format("\"{}\" is not one of \"mr_damper\", \"none\"", plant.specimen));
  }
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
  EffectRigModel m;
  m.rig = LinearRig::Make(plant.actuator, dt_s, damper, plant.damper, plant.cvode_rtol, plant.current_dynamics);
  m.effects = plant.effects;
  m.unmodelled = plant.unmodelled;
  m.noise_seed = plant.noise_seed;
  return m;
}

EffectRig::EffectRig(const EffectRigModel& model)
    : m_(model),
      disp_(model.effects, model.rig.servo.dt_s),
      force_(model.effects, model.rig.servo.dt_s),
      noise_(signal::MakeGaussian(EffectNoiseSeed(model.noise_seed))),
      ode_(5, model.rig.rtol, AbsTol(model.rig), &EffectRig::Rhs, this) {
  m_.rig.damper.Validate();
  // Sample 0: at rest, 0 A (as the linear rig).
  f_ = m_.rig.has_damper ? force_.Force(DamperForceKn(CoefficientsAt(m_.rig.damper, 0.0), damper_, 0.0, 0.0))
                         : 0.0;
  Measure();
}

int EffectRig::Rhs(double t, const double* w, double* wdot, void* self) {
  const auto* me = static_cast<const EffectRig*>(self);
  const LinearServo& servo = me->m_.rig.servo;
  const Eigen::Map<const Eigen::Vector3d> z(w);
  const Eigen::Vector3d zdot = servo.A * z + servo.B * me->u_act_;
  wdot[0] = zdot(0), wdot[1] = zdot(1), wdot[2] = zdot(2);
  // Specimen motion: the servo's x(t) plus the effects' offset, linear over the step.
  const double y = (servo.C * z).value() + (me->d0_ + me->dv_ * t);
  const double ydot = (servo.C * zdot).value() + me->dv_;
  const MrDamperCoefficients coef =
      me->constant_current_
          ? me->coef_
          : CoefficientsAt(me->m_.rig.damper, EffectiveCurrentAt(me->m_.rig.driver, me->current_, t));
  const MrDamperRates r = DamperRates(coef, {w[3], w[4]}, y, ydot);
  wdot[3] = r.ydot_mm_s;
  wdot[4] = r.zdot_mm_s;
  return 0;
}

void EffectRig::Step(double u_mm, double i_cmd_A) {
  const LinearRig& rig = m_.rig;
  const double dt = rig.servo.dt_s;
  if (k_ == 0) {  // the current is set before the test starts: every lag at its steady state
    force_.Reset(i_cmd_A);
    current_ = SteadyState(i_cmd_A);
  }
  // Force path, current: the extra lag, then the model's own current dynamics.
  const double i_lag = force_.Current(i_cmd_A);
  if (rig.current_dynamics) {
    Hold(rig.driver, &current_, i_lag);
  } else {
    current_ = SteadyState(i_lag);
  }
  constant_current_ = AtSteadyState(current_);

  // Displacement path: command effects, the servo (exact ZOH), output effects.
  u_act_ = disp_.Pre(u_mm);
  const double x0 = Output(rig.servo, servo_);
  LinearServoState next = servo_;
  models::Step(rig.servo, &next, u_act_);
  const double x1 = Output(rig.servo, next);
  const double y1 = disp_.Post(x1, f_);

  // The damper, driven by the specimen's motion over the step.
  const double d0 = y_ - x0;
  const double d1 = y1 - x1;
  d0_ = d0;
  dv_ = (d1 - d0) / dt;
  double force = 0.0;
  if (rig.has_damper) {
    if (constant_current_) coef_ = CoefficientsAt(rig.damper, current_.held_A);
    double w[5] = {servo_.z(0), servo_.z(1), servo_.z(2), damper_.y_mm, damper_.z_mm};
    ode_.Advance(0.0, dt, w);
    damper_ = {w[3], w[4]};
  }
  servo_ = next;  // authoritative for x (exact ZOH)
  if (rig.current_dynamics) Advance(rig.driver, &current_);
  if (rig.has_damper) {
    const double ydot = OutputVelocity(rig.servo, servo_) + dv_;
    force = DamperForceKn(CoefficientsAt(rig.damper, EffectiveCurrentA(rig.driver, current_)), damper_, y1, ydot);
  }
  y_ = y1;
  f_ = force_.Force(force) + m_.unmodelled.stiffness_kN_per_mm * y1;
  ++k_;
  Measure();
}

void EffectRig::Measure() {
  double y = y_;
  double f = f_;
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

std::unique_ptr<Rig> MakeEffectRig(const scenario::PlantConfig& plant, double dt_s) {
  return std::make_unique<EffectRig>(EffectRigModel::Make(plant, dt_s));
}

}  // namespace rths::models
