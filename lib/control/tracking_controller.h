#pragma once
/// @file Outer-loop tracking controllers (paper Fig. 3): u_k = u_FF,k + u_FB,k (Eq. 14).
///
/// Step-index contract (docs/lockstep.md): Step() is called once per step k with the desired
/// displacement r_k and its derivatives (desired_t k) and the measurement y_k (measured_t k,
/// which depends on commands up to u_{k-1} only); the returned u_k is held by the plant over
/// [t_k, t_{k+1}). A controller never differentiates the measured displacement.
#include <memory>

#include "control/feedforward.h"
#include "scenario/scenario.h"

namespace rths::control {

/// What the plant reported at sample k (measured_t k).
struct Measurement {
  double y_mm = 0.0;       ///< measured displacement y_k [mm]
  double f_kN = 0.0;       ///< measured force f_k [kN]
  double current_A = 0.0;  ///< effective damper current at t_k [A] (after the driver dynamics)
};

/// One step's command, split into its parts [mm].
struct Command {
  double u_mm = 0.0;
  double u_ff_mm = 0.0;
  double u_fb_mm = 0.0;
};

class TrackingController {
 public:
  virtual ~TrackingController() = default;
  /// Computes u_k. Called exactly once per step, in order. Allocates nothing.
  /// @param d  r_k [mm] and r'_k, r''_k, r'''_k [mm/s^n] (Eqs. 20-22, from the integrator)
  /// @param m  the measurements of sample k
  virtual Command Step(const Derivatives& d, const Measurement& m) = 0;
};

/// `none`: u_k = r_k (no compensation).
class NoCompensation final : public TrackingController {
 public:
  Command Step(const Derivatives& d, const Measurement&) override { return {d.r, d.r, 0.0}; }
};

/// `ff`: the proposed model-inverse feedforward G_FF(s) = (s+p)(s^2+bs+c)/K (Eqs. 16-19):
/// u_k = a0 r_k + a1 r'_k + a2 r''_k + a3 r'''_k, coefficients computed from K and the poles.
class ModelFeedforward final : public TrackingController {
 public:
  ModelFeedforward(const scenario::ServoModel3& model, bool half_step_ahead, double dt_s)
      : a_(MakeFeedforwardCoefficients(model)), half_step_ahead_(half_step_ahead), dt_s_(dt_s) {}
  Command Step(const Derivatives& d, const Measurement&) override {
    const double u = FeedforwardCommand(a_, d, half_step_ahead_, dt_s_);
    return {u, u, 0.0};
  }
  const FeedforwardCoefficients& coefficients() const { return a_; }

 private:
  const FeedforwardCoefficients a_;
  const bool half_step_ahead_;
  const double dt_s_;
};

/// Builds the controller a scenario names. Throws rths::Error for an unknown kind.
std::unique_ptr<TrackingController> MakeTrackingController(const scenario::ControllerConfig& cfg,
                                                           double dt_s);

}  // namespace rths::control
