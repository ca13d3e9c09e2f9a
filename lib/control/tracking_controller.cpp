#include "control/tracking_controller.h"

#include "core/error.h"

namespace rths::control {

std::unique_ptr<TrackingController> MakeTrackingController(const scenario::ControllerConfig& cfg,
                                                           double dt_s) {
  if (cfg.kind == "none") return std::make_unique<NoCompensation>();
  if (cfg.kind == "ff") return std::make_unique<ModelFeedforward>(cfg.model, cfg.half_step_ahead, dt_s);
  throw Error("controller.kind", "unknown controller '" + cfg.kind + "' (allowed: none, ff)");
}

}  // namespace rths::control
