#include "models/servo_physical.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {
namespace {

Error Bad(const char* field, double v, const char* range) {
  return Error(fmt::format("PhysicalActuator: {}", field),
               fmt::format("must be finite and {} (got {})", range, v));
}

}  // namespace

PhysicalActuator PhysicalActuator::Make(const models::PhysicalActuatorConfig& c) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto nonnegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!positive(c.area_m2)) throw Bad("area_m2", c.area_m2, "> 0");
  if (!positive(c.supply_pressure_Pa)) throw Bad("supply_pressure_Pa", c.supply_pressure_Pa, "> 0");
  if (!positive(c.volume_m3)) throw Bad("volume_m3", c.volume_m3, "> 0");
  if (!positive(c.piston_mass_kg)) throw Bad("piston_mass_kg", c.piston_mass_kg, "> 0");
  if (!nonnegative(c.piston_damping_N_s_m))
    throw Bad("piston_damping_N_s_m", c.piston_damping_N_s_m, ">= 0");
  if (!positive(c.valve_hz)) throw Bad("valve_hz", c.valve_hz, "> 0");
  if (!positive(c.valve_zeta)) throw Bad("valve_zeta", c.valve_zeta, "> 0");
  if (!positive(c.kq_m3_s)) throw Bad("kq_m3_s", c.kq_m3_s, "> 0");
  if (!positive(c.kp_per_m)) throw Bad("kp_per_m", c.kp_per_m, "> 0");
  if (!positive(c.beta_Pa)) throw Bad("beta_Pa", c.beta_Pa, "> 0");
  if (!nonnegative(c.leakage_m3_s_Pa)) throw Bad("leakage_m3_s_Pa", c.leakage_m3_s_Pa, ">= 0");
  PhysicalActuator a;
  a.area_m2 = c.area_m2;
  a.supply_pressure_Pa = c.supply_pressure_Pa;
  a.volume_m3 = c.volume_m3;
  a.piston_mass_kg = c.piston_mass_kg;
  a.piston_damping_N_s_m = c.piston_damping_N_s_m;
  a.valve_w_rad_s = 2.0 * std::numbers::pi * c.valve_hz;
  a.valve_zeta = c.valve_zeta;
  a.kq_m3_s = c.kq_m3_s;
  a.kp_per_m = c.kp_per_m;
  a.beta_Pa = c.beta_Pa;
  a.leakage_m3_s_Pa = c.leakage_m3_s_Pa;
  return a;
}

double ValveCommand(const PhysicalActuator& a, double u_m, double x_m) {
  return std::clamp(a.kp_per_m * (u_m - x_m), -1.0, 1.0);
}

double FlowFactor(const PhysicalActuator& a, double xv, double pL_Pa) {
  const double sgn = xv > 0.0 ? 1.0 : (xv < 0.0 ? -1.0 : 0.0);
  // Guard: no flow against a load pressure above supply (the argument would be negative).
  const double arg = (a.supply_pressure_Pa - sgn * pL_Pa) / a.supply_pressure_Pa;
  return arg > 0.0 ? std::sqrt(arg) : 0.0;
}

double LoadFlowM3_s(const PhysicalActuator& a, double xv, double pL_Pa) {
  return a.kq_m3_s * xv * FlowFactor(a, xv, pL_Pa) - a.leakage_m3_s_Pa * pL_Pa;
}

ActuatorState ActuatorRates(const PhysicalActuator& a, const ActuatorState& s, double u_m,
                            double load_N) {
  const double wv = a.valve_w_rad_s;
  const double iv = ValveCommand(a, u_m, s.x_m);
  ActuatorState d;
  d.x_m = s.v_m_s;
  d.v_m_s = (a.area_m2 * s.pL_Pa - load_N - a.piston_damping_N_s_m * s.v_m_s) / a.piston_mass_kg;
  d.pL_Pa = 4.0 * a.beta_Pa / a.volume_m3 *
            (LoadFlowM3_s(a, s.xv, s.pL_Pa) - a.area_m2 * s.v_m_s);
  d.xv = s.xv_rate_per_s;
  d.xv_rate_per_s = wv * wv * (iv - s.xv) - 2.0 * a.valve_zeta * wv * s.xv_rate_per_s;
  return d;
}

std::complex<double> SmallSignalResponse(const PhysicalActuator& a, const SpringDashpot& load,
                                         double f_hz) {
  using cd = std::complex<double>;
  const cd s(0.0, 2.0 * std::numbers::pi * f_hz);
  const double wv = a.valve_w_rad_s;
  const cd valve = wv * wv / (s * s + 2.0 * a.valve_zeta * wv * s + wv * wv);
  const cd z = (a.piston_mass_kg * s * s + (load.c_N_s_m + a.piston_damping_N_s_m) * s +
                load.k_N_m) *
                   (a.volume_m3 / (4.0 * a.beta_Pa) * s + a.leakage_m3_s_Pa) +
               a.area_m2 * a.area_m2 * s;
  const cd loop = a.kp_per_m * a.kq_m3_s * a.area_m2 * valve;
  return loop / (z + loop);
}

PhysicalRig PhysicalRig::Make(const models::PhysicalActuatorConfig& actuator, double dt_s,
                              RigLoad load, bool current_dynamics, const MrDamperParams& damper,
                              const SpringDashpot& spring, double rtol,
                              const CurrentDriverParams& driver) {
  PhysicalRig r;
  r.actuator = PhysicalActuator::Make(actuator);
  if (!(std::isfinite(dt_s) && dt_s > 0.0))
    throw Error("PhysicalRig: dt_s", fmt::format("must be finite and > 0 (got {})", dt_s));
  if (!(rtol > 0.0 && rtol <= 1e-2))
    throw Error("PhysicalRig: rtol", fmt::format("must be in (0, 1e-2] (got {})", rtol));
  if (!(std::isfinite(spring.k_N_m) && spring.k_N_m >= 0.0 && std::isfinite(spring.c_N_s_m) &&
        spring.c_N_s_m >= 0.0))
    throw Error("PhysicalRig: spring",
                fmt::format("k and c must be finite and >= 0 (got {}, {})", spring.k_N_m,
                            spring.c_N_s_m));
  damper.Validate();
  r.load = load;
  r.damper = damper;
  r.spring = spring;
  r.current_dynamics = current_dynamics;
  r.driver = CurrentDriver::Make(driver, dt_s);
  r.dt_s = dt_s;
  r.rtol = rtol;
  return r;
}

double MeasuredDisplacementMm(const PhysicalRig&, const PhysicalRigState& s) {
  return 1e3 * s.actuator.x_m;
}

double EffectiveCurrentA(const PhysicalRig& rig, const PhysicalRigState& s) {
  return EffectiveCurrentA(rig.driver, s.current);
}

double MeasuredForceKn(const PhysicalRig& rig, const PhysicalRigState& s) {
  switch (rig.load) {
    case RigLoad::kNone:
      return 0.0;
    case RigLoad::kSpringDashpot:
      return 1e-3 * (rig.spring.k_N_m * s.actuator.x_m + rig.spring.c_N_s_m * s.actuator.v_m_s);
    case RigLoad::kMrDamper:
      break;
  }
  return DamperForceKn(CoefficientsAt(rig.damper, EffectiveCurrentA(rig, s)), s.damper,
                       1e3 * s.actuator.x_m, 1e3 * s.actuator.v_m_s);
}

namespace {

// Absolute tolerances per ODE state, each in its unit: rtol times a resolution far below what
// the sensors resolve (0.01 mm, 10 mm/s, 1 kPa, 1e-3 of full spool, 1 /s; 0.01 mm for the damper
// states, as in LinearRig).
std::array<double, 7> AbsTol(double rtol) {
  return {rtol * 1e-5, rtol * 1e-2, rtol * 1e3, rtol * 1e-3, rtol * 1.0, rtol * 1e-2, rtol * 1e-2};
}

}  // namespace

PhysicalRigStepper::PhysicalRigStepper(const PhysicalRig& rig)
    : rig_(rig),
      ode_(rig.load == RigLoad::kMrDamper ? 7 : 5, rig.rtol,
           std::span<const double>(AbsTol(rig.rtol).data(),
                                   rig.load == RigLoad::kMrDamper ? 7 : 5),
           &PhysicalRigStepper::Rhs, this) {
  if (rig_.integrator == RigIntegrator::kRk4 && !(rig_.rk4_substeps >= 1 && rig_.rk4_substeps <= 1000))
    throw Error("PhysicalRig: rk4_substeps",
                fmt::format("must be in [1, 1000] (got {})", rig_.rk4_substeps));
}

int PhysicalRigStepper::Rhs(double t, const double* w, double* wdot, void* self) {
  const auto* me = static_cast<const PhysicalRigStepper*>(self);
  const PhysicalRig& rig = me->rig_;
  const ActuatorState s{w[0], w[1], w[2], w[3], w[4]};
  double load_N = 0.0;
  if (rig.load == RigLoad::kSpringDashpot) {
    load_N = rig.spring.k_N_m * s.x_m + rig.spring.c_N_s_m * s.v_m_s;
  } else if (rig.load == RigLoad::kMrDamper) {
    // The damper in its own units: x [mm], x' [mm/s] -> F [kN], rates [mm/s].
    const MrDamperCoefficients coef =
        me->constant_current_
            ? me->coef_
            : CoefficientsAt(rig.damper, EffectiveCurrentAt(rig.driver, me->current_, t));
    const MrDamperState d{w[5], w[6]};
    const double x_mm = 1e3 * s.x_m, v_mm_s = 1e3 * s.v_m_s;
    load_N = 1e3 * DamperForceKn(coef, d, x_mm, v_mm_s);
    const MrDamperRates r = DamperRates(coef, d, x_mm, v_mm_s);
    wdot[5] = r.ydot_mm_s;
    wdot[6] = r.zdot_mm_s;
  }
  const ActuatorState ds = ActuatorRates(rig.actuator, s, me->u_m_, load_N);
  wdot[0] = ds.x_m, wdot[1] = ds.v_m_s, wdot[2] = ds.pL_Pa, wdot[3] = ds.xv,
  wdot[4] = ds.xv_rate_per_s;
  return 0;
}

void PhysicalRigStepper::Step(PhysicalRigState* s, double u_mm, double i_cmd_A) {
  // Current: hold i_k over the step (closed form inside it), or take it as is.
  if (rig_.current_dynamics) {
    Hold(rig_.driver, &s->current, i_cmd_A);
  } else {
    s->current = SteadyState(i_cmd_A);
  }
  current_ = s->current;
  constant_current_ = AtSteadyState(current_);
  if (constant_current_) coef_ = CoefficientsAt(rig_.damper, current_.held_A);
  u_m_ = 1e-3 * u_mm;

  const int n = size();
  double w[7] = {s->actuator.x_m, s->actuator.v_m_s, s->actuator.pL_Pa, s->actuator.xv,
                 s->actuator.xv_rate_per_s, s->damper.y_mm, s->damper.z_mm};
  if (rig_.integrator == RigIntegrator::kCvode) {
    ode_.Advance(0.0, rig_.dt_s, w);
  } else {
    const double h = rig_.dt_s / rig_.rk4_substeps;
    for (int j = 0; j < rig_.rk4_substeps; ++j) {
      const double t = j * h;
      Rhs(t, w, k1_, this);
      for (int i = 0; i < n; ++i) tmp_[i] = w[i] + 0.5 * h * k1_[i];
      Rhs(t + 0.5 * h, tmp_, k2_, this);
      for (int i = 0; i < n; ++i) tmp_[i] = w[i] + 0.5 * h * k2_[i];
      Rhs(t + 0.5 * h, tmp_, k3_, this);
      for (int i = 0; i < n; ++i) tmp_[i] = w[i] + h * k3_[i];
      Rhs(t + h, tmp_, k4_, this);
      for (int i = 0; i < n; ++i) w[i] += h / 6.0 * (k1_[i] + 2.0 * k2_[i] + 2.0 * k3_[i] + k4_[i]);
    }
  }
  s->actuator = {w[0], w[1], w[2], w[3], w[4]};
  if (rig_.load == RigLoad::kMrDamper) s->damper = {w[5], w[6]};
  if (rig_.current_dynamics) Advance(rig_.driver, &s->current);
}

long PhysicalRigStepper::last_internal_steps() const {
  return rig_.integrator == RigIntegrator::kCvode ? ode_.last_steps() : 0;
}

}  // namespace rths::models
