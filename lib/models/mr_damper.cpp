#include "models/mr_damper.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {
namespace {

// Eqs. 35-39: p = p_b + (p_a - p_b) exp(-p_c i).
double AtCurrent(double a, double b, double c, double i) { return b + (a - b) * std::exp(-c * i); }

}  // namespace

void MrDamperParams::Validate() const {
  for (const MrDamperField& f : kMrDamperFields) {
    const double v = this->*f.member;
    if (std::isinf(f.min)) {
      if (!std::isfinite(v)) throw Error(fmt::format("MrDamperParams: {}", f.key), "must be finite");
      continue;
    }
    const bool ok = std::isfinite(v) && (f.strict ? v > f.min : v >= f.min);
    if (!ok)
      throw Error(fmt::format("MrDamperParams: {}", f.key),
                  fmt::format("must be finite and {} {} (got {})", f.strict ? ">" : ">=", f.min, v));
  }
}

MrDamperCoefficients CoefficientsAt(const MrDamperParams& p, double i) {
  return {AtCurrent(p.alpha_a, p.alpha_b, p.alpha_c, i),
          AtCurrent(p.c0_a, p.c0_b, p.c0_c, i),
          AtCurrent(p.c1_a, p.c1_b, p.c1_c, i),
          AtCurrent(p.beta_a, p.beta_b, p.beta_c, i),
          AtCurrent(p.gamma_a, p.gamma_b, p.gamma_c, i),
          p.A, p.n, p.k0, p.k1, p.x0};
}

namespace {

// Eq. 32 solved for y' [mm/s].
double InternalVelocity(const MrDamperCoefficients& k, const MrDamperState& s, double x,
                        double xdot) {
  return (k.alpha * s.z_mm + k.k0 * (x - s.y_mm) + k.c0 * xdot) / (k.c0 + k.c1);
}

}  // namespace

MrDamperRates DamperRates(const MrDamperCoefficients& k, const MrDamperState& s, double x_mm,
                          double xdot_mm_s) {
  const double ydot = InternalVelocity(k, s, x_mm, xdot_mm_s);
  const double v = xdot_mm_s - ydot;  // relative velocity x' - y'
  const double z = s.z_mm;
  double zdot;
  if (k.n == 2.0) {  // Eq. 33 with n = 2
    zdot = -k.gamma * std::abs(v) * z * std::abs(z) - k.beta * v * z * z + k.A * v;
  } else {
    const double zn1 = std::pow(std::abs(z), k.n - 1.0);
    zdot = -k.gamma * std::abs(v) * z * zn1 - k.beta * v * std::abs(z) * zn1 + k.A * v;
  }
  return {ydot, zdot};
}

double DamperForceKn(const MrDamperCoefficients& k, const MrDamperState& s, double x_mm,
                     double xdot_mm_s) {
  const double ydot = InternalVelocity(k, s, x_mm, xdot_mm_s);
  return k.alpha * s.z_mm + k.c0 * (xdot_mm_s - ydot) + k.k0 * (x_mm - s.y_mm) +
         k.k1 * (x_mm - k.x0);
}

namespace {

const MrDamperParams& Validated(const MrDamperParams& p) {
  p.Validate();
  return p;
}

}  // namespace

MrDamperStepper::MrDamperStepper(const MrDamperParams& params, Motion motion, void* motion_ctx,
                                 double rtol, OdeMethod method)
    : params_(Validated(params)),
      motion_(motion),
      motion_ctx_(motion_ctx),
      ode_(2, rtol, rtol * 0.01, &MrDamperStepper::Rhs, this, method) {
  if (motion == nullptr) throw Error("MrDamperStepper", "motion is null");
}

int MrDamperStepper::Rhs(double t, const double* x, double* xdot, void* self) {
  const auto* me = static_cast<const MrDamperStepper*>(self);
  double xm, vm;
  me->motion_(t, me->motion_ctx_, &xm, &vm);
  const MrDamperRates r = DamperRates(me->coef_, {x[0], x[1]}, xm, vm);
  xdot[0] = r.ydot_mm_s;
  xdot[1] = r.zdot_mm_s;
  return 0;
}

void MrDamperStepper::Advance(double t0_s, double t1_s, double current_A, MrDamperState* s) {
  coef_ = CoefficientsAt(params_, current_A);
  double x[2] = {s->y_mm, s->z_mm};
  ode_.Advance(t0_s, t1_s, x);
  s->y_mm = x[0];
  s->z_mm = x[1];
}

double MrDamperStepper::ForceKn(double t_s, double current_A, const MrDamperState& s) const {
  double xm, vm;
  motion_(t_s, motion_ctx_, &xm, &vm);
  return DamperForceKn(CoefficientsAt(params_, current_A), s, xm, vm);
}

}  // namespace rths::models
