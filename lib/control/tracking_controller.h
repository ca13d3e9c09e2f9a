#pragma once
/// @file Outer-loop tracking controllers (paper Fig. 3): u_k = u_FF,k + u_FB,k (Eq. 14).
///
/// Step-index contract (docs/lockstep.md): Step() is called once per step k with the desired
/// displacement r_k and its derivatives (desired_t k) and the measurement y_k (measured_t k,
/// which depends on commands up to u_{k-1} only); the returned u_k is held by the plant over
/// [t_k, t_{k+1}). A controller never differentiates the measured displacement.
///
/// Every kind of Table 1 (docs/controllers.md): `none`, `ff` (here), `poly3` and `lead`
/// (baselines.h), `ff_lp` and `bumpless_lp` (inverse_lowpass.h), `ff_lqg` (lqg.h). A controller is
/// an immutable design, computed once in its constructor, plus its per-step state.
#include <array>
#include <memory>

#include "control/feedforward.h"
#include "control/lti.h"
#include "control/controller_config.h"

namespace rths::control {

/// What the plant reported at sample k (measured_t k).
struct Measurement {
  double y_mm = 0.0;       ///< measured displacement y_k [mm]
  double f_kN = 0.0;       ///< measured force f_k [kN]
  double current_A = 0.0;  ///< effective damper current at t_k [A] (after the driver dynamics)
};

/// Most coefficients an adaptive controller reports per step (command_t.adapt).
inline constexpr int kMaxAdaptive = 4;

/// One step's command, split into its parts [mm], and an adaptive controller's coefficients.
struct Command {
  double u_mm = 0.0;
  double u_ff_mm = 0.0;
  double u_fb_mm = 0.0;
  /// Number of adaptive coefficients in use this step (0 for a fixed controller).
  int n_adapt = 0;
  /// The coefficients of u = sum_i adapt[i] x_t^(i) used for u_k: a_0 [-], a_1 [s], a_2 [s^2], a_3 [s^3].
  std::array<double, kMaxAdaptive> adapt{};
};

/// A controller as linear discrete maps (for analysis; docs/controllers.md):
///   u_k = F(z) r_k + C_fb(z) e_k,  e_k = y_k - r_k  (the deviation output of Eq. 13),
/// with F taking r_k, r_{k-1}, ... (the derivatives of Eqs. 20-22 folded in, as the integrator
/// computes them) and C_fb = 0 without feedback.
struct ControllerLti {
  DiscreteSs ff;               ///< F(z): r -> u_FF
  bool has_feedback = false;
  DiscreteSs fb;               ///< C_fb(z): e -> u_FB (has direct feedthrough: u_k uses e_k)
};

class TrackingController {
 public:
  virtual ~TrackingController() = default;
  /// Computes u_k. Called exactly once per step, in order. Allocates nothing.
  /// @param d  r_k [mm] and r'_k, r''_k, r'''_k [mm/s^n] (Eqs. 20-22, from the integrator)
  /// @param m  the measurements of sample k
  virtual Command Step(const Derivatives& d, const Measurement& m) = 0;
  /// The design as linear maps at a constant effective current [A] (only `bumpless_lp` depends on
  /// it). Independent of the per-step state; allocates.
  virtual ControllerLti Linearize(double current_A) const = 0;
};

/// `none`: u_k = r_k (no compensation).
class NoCompensation final : public TrackingController {
 public:
  explicit NoCompensation(double dt_s) : dt_s_(dt_s) {}
  Command Step(const Derivatives& d, const Measurement&) override { return {d.r, d.r, 0.0}; }
  ControllerLti Linearize(double) const override { return {StaticGain(1.0, dt_s_), false, {}}; }

 private:
  const double dt_s_;
};

/// Throws rths::Error(key, ...) unless K, p, b, c are finite and > 0 (stable, minimum phase).
void RequireServoModel(const models::ServoModel3& m, const std::string& key);
/// MakeFeedforwardCoefficients(m), with errors naming the scenario key (e.g. "controller.model").
FeedforwardCoefficients FeedforwardFor(const models::ServoModel3& m, const std::string& key);

/// F(z) of the feedforward u = a0 r + a1 r' + a2 r'' + a3 r''' (Eq. 19, or half a step ahead) with
/// the derivatives of Eqs. 20-22: an FIR filter on r_k .. r_{k-3}.
DiscreteSs FeedforwardFir(const FeedforwardCoefficients& a, bool half_step_ahead, double dt_s);

/// `ff`: the proposed model-inverse feedforward G_FF(s) = (s+p)(s^2+bs+c)/K (Eqs. 16-19):
/// u_k = a0 r_k + a1 r'_k + a2 r''_k + a3 r'''_k, coefficients computed from K and the poles.
class ModelFeedforward final : public TrackingController {
 public:
  ModelFeedforward(const models::ServoModel3& model, bool half_step_ahead, double dt_s)
      : a_(MakeFeedforwardCoefficients(model)), half_step_ahead_(half_step_ahead), dt_s_(dt_s) {}
  Command Step(const Derivatives& d, const Measurement&) override {
    const double u = FeedforwardCommand(a_, d, half_step_ahead_, dt_s_);
    return {u, u, 0.0};
  }
  ControllerLti Linearize(double) const override {
    return {FeedforwardFir(a_, half_step_ahead_, dt_s_), false, {}};
  }
  const FeedforwardCoefficients& coefficients() const { return a_; }

 private:
  const FeedforwardCoefficients a_;
  const bool half_step_ahead_;
  const double dt_s_;
};

/// Builds the controller a scenario names, designing it from the scenario's models. Throws
/// rths::Error naming the key ("controller.kind", "controller.delay_ms", "controller.lqg", ...)
/// for an unknown kind or a design that fails.
std::unique_ptr<TrackingController> MakeTrackingController(const control::ControllerConfig& cfg,
                                                           double dt_s);

}  // namespace rths::control
