#include "models/linear_rig.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

LinearRig LinearRig::Make(const models::ServoModel3& actuator, double dt_s, bool has_damper,
                          const MrDamperParams& damper, double rtol, bool current_dynamics,
                          const CurrentDriverParams& driver) {
  if (!(rtol > 0.0 && rtol <= 1e-2))
    throw Error("LinearRig: rtol", fmt::format("must be in (0, 1e-2] (got {})", rtol));
  damper.Validate();
  LinearRig r;
  r.servo = LinearServo::Make(actuator, dt_s);
  r.damper = damper;
  r.has_damper = has_damper;
  r.rtol = rtol;
  r.current_dynamics = current_dynamics;
  r.driver = CurrentDriver::Make(driver, dt_s);
  return r;
}

double MeasuredDisplacementMm(const LinearRig& rig, const LinearRigState& s) {
  return Output(rig.servo, s.servo);
}

double MeasuredForceKn(const LinearRig& rig, const LinearRigState& s, double current_A) {
  if (!rig.has_damper) return 0.0;
  return DamperForceKn(CoefficientsAt(rig.damper, current_A), s.damper, Output(rig.servo, s.servo),
                       OutputVelocity(rig.servo, s.servo));
}

double EffectiveCurrentA(const LinearRig& rig, const LinearRigState& s) {
  return EffectiveCurrentA(rig.driver, s.current);
}

double MeasuredForceKn(const LinearRig& rig, const LinearRigState& s) {
  return MeasuredForceKn(rig, s, EffectiveCurrentA(rig, s));
}

namespace {

// Absolute tolerances: rtol times 0.01 mm for displacements, scaled by the servo's pole size
// w = d0^(1/3) [1/s] for its velocity and acceleration states.
std::array<double, 5> AbsTol(const LinearRig& rig) {
  const double w = std::cbrt(-rig.servo.A(2, 0));
  const double a = rig.rtol * 0.01;
  return {a, a * w, a * w * w, a, a};
}

}  // namespace

LinearRigStepper::LinearRigStepper(const LinearRig& rig)
    : rig_(rig), ode_(5, rig.rtol, AbsTol(rig), &LinearRigStepper::Rhs, this) {
  rig_.damper.Validate();
}

int LinearRigStepper::Rhs(double t, const double* w, double* wdot, void* self) {
  const auto* me = static_cast<const LinearRigStepper*>(self);
  const LinearServo& servo = me->rig_.servo;
  const Eigen::Map<const Eigen::Vector3d> z(w);
  const Eigen::Vector3d zdot = servo.A * z + servo.B * me->u_mm_;
  wdot[0] = zdot(0), wdot[1] = zdot(1), wdot[2] = zdot(2);
  const double x = (servo.C * z).value();
  const double xdot = (servo.C * zdot).value();  // C A z (C B = 0: strictly proper)
  const MrDamperCoefficients coef =
      me->constant_current_
          ? me->coef_
          : CoefficientsAt(me->rig_.damper, EffectiveCurrentAt(me->rig_.driver, me->current_, t));
  const MrDamperRates r = DamperRates(coef, {w[3], w[4]}, x, xdot);
  wdot[3] = r.ydot_mm_s;
  wdot[4] = r.zdot_mm_s;
  return 0;
}

void LinearRigStepper::Step(LinearRigState* s, double u_mm, double current_A) {
  if (rig_.current_dynamics) {
    Hold(rig_.driver, &s->current, current_A);  // i_c(t) in closed form over the step
  } else {
    s->current = SteadyState(current_A);
  }
  current_ = s->current;
  constant_current_ = AtSteadyState(current_);
  if (rig_.has_damper) {
    u_mm_ = u_mm;
    if (constant_current_) coef_ = CoefficientsAt(rig_.damper, current_.held_A);
    double w[5] = {s->servo.z(0), s->servo.z(1), s->servo.z(2), s->damper.y_mm, s->damper.z_mm};
    ode_.Advance(0.0, rig_.servo.dt_s, w);
    s->damper = {w[3], w[4]};
  }
  models::Step(rig_.servo, &s->servo, u_mm);  // exact ZOH, authoritative for y
  if (rig_.current_dynamics) Advance(rig_.driver, &s->current);
}

}  // namespace rths::models
