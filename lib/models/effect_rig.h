#pragma once
/// @file The rig mode of procs/plant (docs/rig_mode.md): the linear rig (Eqs. 28-30 + the MR
/// damper, lib/models/linear_rig.h) with effects of the library (lib/models/rig_effects.h)
/// switched on, plus two disturbances outside the library (models::UnmodelledConfig), seeded.
/// This is how a user rehearses a real rig, and how the diagnosis is tested. Units: mm, kN, A, s.
///
/// One step k -> k+1, command u_k [mm] and commanded current i_k [A] held over [t_k, t_{k+1}):
///
///     i_l   = ForceEffects::Current(i_k)                       current_lag (identity if off)
///     i_c(t)  the model's current dynamics (Eq. 40 + 75 Hz, closed form) driven by i_l held,
///             or i_l itself without them (plant.current_dynamics)
///     v_k   = DisplacementEffects::Pre(u_k)                    pure_delay, gain_error
///     z_{k+1} = Phi z_k + Gamma v_k,   x_{k+1} = C z_{k+1}     linear servo, exact ZOH (with the flow
///             limit in the loop, servovalve_saturation in_loop = 1: FlowLimitedServo, RK4)
///     y_{k+1} = DisplacementEffects::Post(x_{k+1}, f_k)        oil column, saturation, load
///                                                              coupling, friction, backlash (**)
///     damper  Eqs. 32-33 integrated by ARKODE over the step, driven by the specimen motion
///             y(t) = x(t) + d_k + (d_{k+1} - d_k) (t - t_k) / dt,   d = y - x      (*)
///             y'(t) = x'(t) + (d_{k+1} - d_k) / dt
///             with x(t), x'(t) the servo's continuous motion (its states in the same ODE)
///     f_{k+1} = ForceEffects::Force(F_{k+1}) + k_u y_{k+1}     damper_scale; unmodelled spring
///             F_{k+1} = Eq. 34 at y_{k+1}, y'(t_{k+1}^-), i_c(t_{k+1})
///     (y_s, f_s) = MeasurementEffects::Measure(y_{k+1}, a_{k+1}, f_{k+1})  load_cell_inertia
///             (+ m a, a the servo's y'' plus the effects' second difference), channel_skew
///     measured: y_m = y_s + a sin(2 pi f_r t_{k+1}) + n_y,  f_m = f_s + n_f
///
/// (*) The choice of the specimen motion inside a step: the servo's own continuous motion plus
/// a linear interpolation of what the effects add at the samples. Without displacement effects
/// (d = 0) it is exactly the linear rig's damper drive, so a rig with only force-path effects
/// (or identity ones) gives the linear rig's y and f bit for bit; with effects, y(t) passes
/// through every sample y_k and its velocity is the effects' mean rate over the step (a backlash
/// that holds gives y' = x' - (x_{k+1} - x_k)/dt, close to 0; a rate limit gives y' ~ vmax).
///
/// (**) The load-coupling input is the specimen's true force (before noise, with the unmodelled
/// spring) of the previous sample, f_k: y_{k+1} = x_{k+1} - c f_k, the library's form, which the
/// diagnosis fits from the measured force. Closed around the stiff damper this one-sample loop
/// diverges once c (K + 2 B / dt) > 1 (K = alpha A, B = c0 c1 / (c0 + c1): at 2.5 A and
/// dt = 0.5 ms for c > 7e-4 mm/kN, at 0 A for c > 2.9e-3 mm/kN). With coupling_same_sample
/// (`same_sample = true`) the input is f_{k+1} of the same sample, which depends on y_{k+1}: the
/// step is solved for it (Illinois regula falsi, each trial re-integrating the step from the
/// saved state; 2-4 trials). A real series compliance is passive, and so is this form: stable at
/// any c >= 0. The two differ by c (f_{k+1} - f_k).
///
/// Noise: effects.sensor_noise is drawn here, from a
/// Gaussian stream seeded with a value derived from plant.noise_seed (SplitMix64 of it), one
/// deviate per channel whose rms is > 0, y first, once per sample (sample 0 at construction);
/// the plant participant still adds the baseline plant.noise_* from its own stream on top, so
/// the measured noise has rms sqrt(baseline^2 + effect^2). Same seed, same bits.
#include <cstdint>
#include <memory>
#include <optional>

#include "models/current_driver.h"
#include "models/linear_rig.h"
#include "models/mr_damper.h"
#include "models/ode.h"
#include "models/rig.h"
#include "models/rig_effects.h"
#include "models/servo_flow_limit.h"
#include "models/servo_linear.h"
#include "models/rig.h"
#include "signal/random.h"

namespace rths::models {

/// Immutable description of the rig with effects.
struct EffectRigModel {
  LinearRig rig;                           ///< servo, damper, current dynamics, ODE tolerance
  EffectSet effects;                       ///< library effects that are on
  models::UnmodelledConfig unmodelled;   ///< ripple on y, extra spring on f
  std::uint64_t noise_seed = 7;            ///< plant.noise_seed (the stream is derived from it)
  /// load_coupling with the same-sample force f_{k+1} (solved per step) instead of f_k (**).
  bool coupling_same_sample = false;

  /// From the scenario's plant (kind must be "linear"; specimen "mr_damper" | "none") at the step
  /// dt_s [s]. Validates everything; throws rths::Error naming the bad key.
  static EffectRigModel Make(const models::PlantConfig& plant, double dt_s);
};

/// The seed of the rig's own noise stream, derived from plant.noise_seed (SplitMix64 finaliser),
/// so that it differs from the plant participant's baseline stream seeded with noise_seed itself.
std::uint64_t EffectNoiseSeed(std::uint64_t noise_seed);

/// models::Rig with effects (the @file's step). Step() allocates nothing.
class EffectRig final : public Rig {
 public:
  explicit EffectRig(const EffectRigModel& model);
  EffectRig(const EffectRig&) = delete;
  EffectRig& operator=(const EffectRig&) = delete;

  void Step(double u_mm, double i_cmd_A) override;
  double y_mm() const override { return y_meas_; }
  double f_kN() const override { return f_meas_; }
  double current_A() const override { return EffectiveCurrentA(m_.rig.driver, current_); }
  std::int64_t k() const override { return k_; }

  /// The specimen's displacement y_k [mm] and force f_k [kN] before noise and ripple.
  double true_y_mm() const { return y_; }
  double true_f_kN() const { return f_; }
  /// The actuator model's output x_k [mm] (before the displacement effects).
  double actuator_x_mm() const { return limited_ ? loop_.x : Output(m_.rig.servo, servo_); }
  const EffectRigModel& model() const { return m_; }
  /// load_coupling: steps whose same-sample force had no root to the tolerance (the closest
  /// trial was taken; happens at reversals with coulomb_friction, whose steep sign makes the
  /// force jump).
  std::int64_t unconverged_steps() const { return unconverged_steps_; }

 private:
  static int Rhs(double t, const double* w, double* wdot, void* self);
  /// One integration of the step for a candidate specimen displacement y1 at its end: sets the
  /// motion (d0_, dv_), integrates the damper from the saved state into *damper, returns the total
  /// force f_{k+1} [kN] (damper_scale, unmodelled spring) at the effective current i_end_A.
  double Trial(double x0, double x1, double x1_dot, double y1, double i_end_A, MrDamperState* damper);
  void Measure();  // noise and ripple for the current sample
  static constexpr int kMaxCouplingIterations = 20;

  const EffectRigModel m_;
  DisplacementEffects disp_;
  ForceEffects force_;
  MeasurementEffects meas_;
  DisplacementEffects scratch_;   // load_coupling: trial copy of disp_ (same sizes)
  signal::GaussianState noise_;
  LinearServoState servo_{};
  /// servovalve_saturation in the loop: the actuator with its flow limit (models/servo_flow_limit.h)
  /// instead of servo_; the damper's ODE then carries its state as [x, xv, w].
  std::optional<FlowLimitedServo> limited_;
  FlowLimitedServoState loop_{};
  MrDamperState damper_{};
  CurrentDriverState current_{};
  // within the step being integrated
  double u_act_ = 0.0;            // servo input
  double d0_ = 0.0;               // y - x at the step's start [mm]
  double dv_ = 0.0;               // (d_{k+1} - d_k) / dt [mm/s] (without supply_ripple's share)
  bool ripple_in_step_ = false;   // supply_ripple's continuous motion is added in Rhs
  double ripple_t0_s_ = 0.0;      // ... its time at the step's start [s]
  MrDamperCoefficients coef_{};   // at a constant current
  bool constant_current_ = true;
  // sample k
  double y_ = 0.0, f_ = 0.0;      // true specimen displacement and force
  double y_meas_ = 0.0, f_meas_ = 0.0;
  double f_prev_ = 0.0;           // load_coupling: f_{k-1}, for the first trial
  double d_prev_ = 0.0, d_prev2_ = 0.0;  // y - x at the last two samples (the effects' acceleration)
  std::int64_t k_ = 0;
  std::int64_t unconverged_steps_ = 0;
  OdeStepper ode_;
};

/// The rig-mode rig for `plant` (EffectRigModel::Make + EffectRig).
std::unique_ptr<Rig> MakeEffectRig(const models::PlantConfig& plant, double dt_s);

}  // namespace rths::models
