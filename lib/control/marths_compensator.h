#pragma once
/// @file The maRTHS benchmark's compensators on both actuators, stepped once per sample (docs/marths.md
/// "Compensators"): the one piece of code the in-process loop (studies/marths_loop.h) and the
/// lockstep's controller (participants/marths_participants.h) both run.
///
/// Sample k, targets x_t,k and measured strokes y_k [mm] -> commands u_k [mm]:
///   none     u_k = x_t,k
///   rodeac   u_k,i = RodeacStep(x_t,k,i, y_k,i)                    (control/rodeac.h)
///   ff       u_k,i = the paper's feedforward of x_t,i (Eqs. 17-22) on design model i
///   ff_lqg   the same plus its LQG feedback on y_k,i - x_t,k,i
///   mimo_ff  u_k = H^-1(z) x_t,k                                     (control/mimo_feedforward.h)
/// ff and ff_lqg take each actuator's derivatives by Eqs. 20-22 from its own target sequence.
#include <memory>
#include <optional>

#include <Eigen/Core>

#include "control/controller_config.h"
#include "control/feedforward.h"
#include "control/marths_config.h"
#include "control/mimo_feedforward.h"
#include "control/rodeac.h"
#include "control/tracking_controller.h"

namespace rths::control {

/// What the compensators are built from.
struct MarthsCompensatorSpec {
  MarthsCompensator kind = MarthsCompensator::kNone;
  RodeacDesign rodeac[2];                ///< rodeac: actuator 1, 2
  ControllerConfig per_actuator[2];      ///< ff, ff_lqg: each actuator's (kind set from `kind`)
  models::marths::PlantZpk design_plant = models::marths::NominalPlantZpk();  ///< mimo_ff inverts it
};

/// One run's compensators with their state (the per-actuator laws keep theirs inside).
class MarthsCompensators {
 public:
  /// Designs them at dt_s [s]. Throws rths::Error for a design that fails.
  MarthsCompensators(const MarthsCompensatorSpec& spec, double dt_s);
  /// u_k [mm] from the targets and measured strokes of sample k [mm]. Call once per sample, in
  /// order. Allocates nothing.
  Eigen::Vector2d Step(const Eigen::Vector2d& target_mm, const Eigen::Vector2d& y_mm);
  /// Actuator i's feedforward and feedback parts of the last command (ff, ff_lqg; else u and 0).
  Command Last(int i) const { return last_[i]; }

 private:
  MarthsCompensatorSpec spec_;
  double dt_s_;
  RodeacState rodeac_[2];
  std::unique_ptr<TrackingController> law_[2];
  ExtrapolationState extrapolation_[2];
  std::optional<MimoFeedforward> mimo_;
  MimoFeedforwardState mimo_s_;
  Command last_[2]{};
};

}  // namespace rths::control
