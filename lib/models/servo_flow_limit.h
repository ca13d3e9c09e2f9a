#pragma once
/// @file The servohydraulic actuator with its flow limit inside the servo loop
/// (servovalve_saturation with in_loop = 1, models/rig_effects.h; docs/rig_mode.md "Flow limit").
/// Units: mm, s.
///
/// The three-pole model G(s) = K / ((s + p)(s^2 + b s + c)) (models/servo_linear.h) realised in
/// cascade form, the piston's velocity (the valve's flow over the piston's area) limited:
///     w'  = -p w + K u          (the valve's opening, driven by the loop's command u)
///     xv' = w - b xv - c x      (the piston's velocity as the linear loop would make it)
///     x'  = sat(xv),  sat(v) = clamp(v, -vmax, vmax)
/// Below the limit it is the linear model exactly (x' = xv). At the limit the piston moves at
/// vmax while xv, the loop's own state, keeps growing: the loop winds up and the piston overshoots
/// when it lets go, which a limiter on the actuator's output (in_loop = 0) does not do.
/// A step is the exact ZOH of the linear model (LinearServo, in its phase variables
/// [x, xv, xv'] = [x, xv, w - b xv - c x]) when |xv| stays below kLinearStepMargin vmax at both
/// ends; else classical RK4 with kFlowLimitSubsteps substeps, u held over the step (ZOH). Without
/// the limit the RK4 steps agree with the exact ZOH to 2e-8 mm on a 7 mm motion at 2 kHz
/// (tests/models/rig_effects_test.cpp).
#include "models/servo_linear.h"

namespace rths::models {

/// RK4 substeps per step of FlowLimitedServo where the limit may act.
inline constexpr int kFlowLimitSubsteps = 4;
/// A step whose |xv| stays below this fraction of vmax at both ends is the linear model's exact ZOH.
inline constexpr double kLinearStepMargin = 0.95;

/// Immutable description.
struct FlowLimitedServo {
  double K = 0, p = 0, b = 0, c = 0;  ///< G(s)'s coefficients (ServoModel3)
  double vmax_mm_s = 0;               ///< the flow limit [mm/s], > 0
  double dt_s = 0;                    ///< step [s]
  LinearServo linear;                 ///< the same model without the limit (its exact ZOH)
  /// Throws rths::Error unless K, p, b, c, vmax_mm_s and dt_s are finite and > 0.
  static FlowLimitedServo Make(const ServoModel3& m, double vmax_mm_s, double dt_s);
  /// The same servo as `linear` (its K, p, b, c and dt) with the limit.
  static FlowLimitedServo Make(const LinearServo& linear, double vmax_mm_s);
};

/// Per-step state (cascade form, file comment).
struct FlowLimitedServoState {
  double w = 0.0;   ///< the valve's state [mm/s^2]
  double x = 0.0;   ///< the piston's displacement [mm]
  double xv = 0.0;  ///< the loop's velocity state [mm/s]
};

/// The piston's velocity x' = sat(xv) [mm/s].
double Velocity(const FlowLimitedServo& m, const FlowLimitedServoState& s);
/// The piston's acceleration x'' [mm/s^2]: xv' below the limit, 0 at it (the velocity held at vmax).
double Acceleration(const FlowLimitedServo& m, const FlowLimitedServoState& s);
/// One step with the command u_mm [mm] held. Allocates nothing.
void Step(const FlowLimitedServo& m, FlowLimitedServoState* s, double u_mm);
/// The state's derivative (w', x', xv') for the command u_mm [mm] (for an integrator that carries
/// the servo in its own state: the rig mode's damper ODE).
void Derivative(const FlowLimitedServo& m, const double* state, double u_mm, double* dstate);

}  // namespace rths::models
