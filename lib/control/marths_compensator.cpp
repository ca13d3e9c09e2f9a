#include "control/marths_compensator.h"

namespace rths::control {

MarthsCompensators::MarthsCompensators(const MarthsCompensatorSpec& spec, double dt_s) : spec_(spec), dt_s_(dt_s) {
  switch (spec_.kind) {
    case MarthsCompensator::kRodeac:
      for (int i = 0; i < 2; ++i) rodeac_[i] = RodeacAtRest(spec_.rodeac[i]);
      break;
    case MarthsCompensator::kFf:
    case MarthsCompensator::kFfLqg:
      for (int i = 0; i < 2; ++i) {
        ControllerConfig c = spec_.per_actuator[i];
        c.kind = spec_.kind == MarthsCompensator::kFfLqg ? ControllerKind::kFfLqg : ControllerKind::kFf;
        law_[i] = MakeTrackingController(c, dt_s_);
      }
      break;
    case MarthsCompensator::kMimoFf:
      mimo_ = MakeMimoFeedforward(spec_.design_plant, dt_s_);
      break;
    case MarthsCompensator::kNone:
      break;
  }
}

Eigen::Vector2d MarthsCompensators::Step(const Eigen::Vector2d& target_mm, const Eigen::Vector2d& y_mm) {
  Eigen::Vector2d u = target_mm;
  switch (spec_.kind) {
    case MarthsCompensator::kRodeac:
      for (int i = 0; i < 2; ++i) u(i) = RodeacStep(spec_.rodeac[i], &rodeac_[i], target_mm(i), y_mm(i));
      break;
    case MarthsCompensator::kFf:
    case MarthsCompensator::kFfLqg:
      for (int i = 0; i < 2; ++i) {
        const Derivatives d = StepDerivatives(&extrapolation_[i], target_mm(i), dt_s_);
        last_[i] = law_[i]->Step(d, {y_mm(i), 0.0, 0.0});
        u(i) = last_[i].u_mm;
      }
      return u;
    case MarthsCompensator::kMimoFf:
      u = MimoFeedforwardStep(*mimo_, &mimo_s_, target_mm(0), target_mm(1));
      break;
    case MarthsCompensator::kNone:
      break;
  }
  for (int i = 0; i < 2; ++i) last_[i] = {u(i), u(i), 0.0};
  return u;
}

}  // namespace rths::control
