#include "control/tracking_controller.h"

#include <cmath>

#include <fmt/format.h>

#include "control/ambc.h"
#include "control/ats.h"
#include "control/baselines.h"
#include "control/inverse_lowpass.h"
#include "control/lqg.h"
#include "control/lti_controller.h"
#include "core/error.h"

namespace rths::control {

void RequireServoModel(const models::ServoModel3& m, const std::string& key) {
  for (double v : {m.K, m.p, m.b, m.c}) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw Error(key, fmt::format("servo model \"{}\" (K = {}, p = {}, b = {}, c = {}): all must be finite "
                                   "and > 0 (a stable, minimum-phase model)",
                                   m.name, m.K, m.p, m.b, m.c));
    }
  }
}

FeedforwardCoefficients FeedforwardFor(const models::ServoModel3& m, const std::string& key) {
  RequireServoModel(m, key);
  return MakeFeedforwardCoefficients(m);
}

DiscreteSs FeedforwardFir(const FeedforwardCoefficients& a, bool half_step_ahead, double dt_s) {
  // The map r -> u is linear in (r_k, r_{k-1}, r_{k-2}, r_{k-3}): its taps are the responses to
  // unit vectors, through the same Eqs. 20-22 the integrator uses.
  Eigen::Vector4d h;
  for (int j = 0; j < 4; ++j) {
    ExtrapolationState past;
    past.r1 = j == 1, past.r2 = j == 2, past.r3 = j == 3;
    h(j) = FeedforwardCommand(a, ExtrapolateDerivatives(past, j == 0, dt_s), half_step_ahead, dt_s);
  }
  return Fir(h, dt_s);
}

std::unique_ptr<TrackingController> MakeTrackingController(const control::ControllerConfig& cfg,
                                                           double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  const ControllerKind k = cfg.kind;
  if (k == ControllerKind::kPoly3 || k == ControllerKind::kLead) {
    if (!(cfg.delay_ms <= cfg.max_delay_ms)) {
      throw Error("controller.delay_ms",
                  fmt::format("{} ms: allowed (0, controller.max_delay_ms = {} ms] (extrapolation beyond it "
                              "amplifies noise too much)",
                              cfg.delay_ms, cfg.max_delay_ms));
    }
  }
  if (k == ControllerKind::kNone) return std::make_unique<NoCompensation>(dt_s);
  if (k == ControllerKind::kFf) {
    RequireServoModel(cfg.model, "controller.model");
    return std::make_unique<ModelFeedforward>(cfg.model, cfg.half_step_ahead, dt_s);
  }
  if (k == ControllerKind::kPoly3) return std::make_unique<PolynomialExtrapolation>(MakePoly3(cfg.delay_ms * 1e-3, dt_s), dt_s);
  if (k == ControllerKind::kLead) {
    return std::make_unique<LeadCompensator>(MakeLead(cfg.delay_ms * 1e-3, cfg.lead_tp_ms * 1e-3, dt_s), dt_s);
  }
  if (k == ControllerKind::kFfLp) {
    return std::make_unique<InverseLowpass>(
        MakeInverseLowpass(cfg.model, cfg.lp_order, cfg.lp_cutoff_hz, dt_s, "controller.model"));
  }
  if (k == ControllerKind::kBumplessLp) {
    return std::make_unique<BumplessInverseLowpass>(
        MakeInverseLowpass(cfg.model_low, cfg.lp_order, cfg.lp_cutoff_hz, dt_s, "controller.model_low"),
        MakeInverseLowpass(cfg.model_high, cfg.lp_order, cfg.lp_cutoff_hz, dt_s, "controller.model_high"),
        cfg.current_high_A);
  }
  if (k == ControllerKind::kFfLqg) return std::make_unique<FeedforwardLqg>(cfg.model, cfg.lqg, cfg.half_step_ahead, dt_s);
  if (k == ControllerKind::kLti) return std::make_unique<LtiController>(MakeLtiDesign(cfg.lti, dt_s));
  if (k == ControllerKind::kAts) return std::make_unique<AtsController>(MakeAtsDesign(cfg.ats, dt_s));
  if (k == ControllerKind::kAmbc) return std::make_unique<AmbcController>(MakeAmbcDesign(cfg.ambc, cfg.model, dt_s));
  throw Error("controller.kind", "unknown controller");
}

}  // namespace rths::control
