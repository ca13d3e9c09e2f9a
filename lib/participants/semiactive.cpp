#include "participants/semiactive.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "participants/factory.h"

namespace rths::participants {

CurrentSchedule::CurrentSchedule(const scenario::SemiactiveConfig& cfg, double dt_s) {
  if (cfg.mode == "passive_off") {
    on_A_ = 0.0;
  } else if (cfg.mode == "passive_on") {
    on_A_ = cfg.max_current_A;
  } else if (cfg.mode == "constant") {
    on_A_ = cfg.current_A;
  } else if (cfg.mode == "pulse") {
    on_A_ = cfg.max_current_A;
    period_ = std::max<std::int64_t>(2, std::llround(1.0 / (cfg.pulse_hz * dt_s)));
    on_steps_ = std::llround(cfg.pulse_duty * static_cast<double>(period_));
  } else {
    throw Error("semiactive.mode", "'" + cfg.mode +
                                       "' is not a schedule (allowed: passive_off, passive_on, constant, pulse)");
  }
  if (cfg.mode != "pulse") on_steps_ = period_;
}

double CurrentSchedule::At(std::int64_t k) const { return k % period_ < on_steps_ ? on_A_ : 0.0; }

Semiactive::Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm)
    : DesiredMeasuredParticipant("semiactive", std::move(id), TimingOf(s), lcm, lockstep::kChCurrent),
      schedule_(s.semiactive, s.run.dt_s) {}

void Semiactive::Compute(std::int64_t k, const rths::desired_t&, const rths::measured_t&,
                         rths::current_t* out) {
  out->i_cmd_A = schedule_.At(k);
}

}  // namespace rths::participants
