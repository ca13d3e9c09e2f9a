#include "participants/semiactive.h"

#include "core/error.h"
#include "participants/factory.h"

namespace rths::participants {

double ConstantCurrentA(const scenario::SemiactiveConfig& cfg) {
  if (cfg.mode == "passive_off") return 0.0;
  if (cfg.mode == "passive_on") return cfg.max_current_A;
  if (cfg.mode == "constant") return cfg.current_A;
  throw Error("semiactive.mode",
              "unknown mode '" + cfg.mode + "' (allowed: passive_off, passive_on, constant)");
}

Semiactive::Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm)
    : DesiredMeasuredParticipant("semiactive", std::move(id), TimingOf(s), lcm, lockstep::kChCurrent),
      current_A_(ConstantCurrentA(s.semiactive)) {}

void Semiactive::Compute(std::int64_t, const rths::desired_t&, const rths::measured_t&,
                         rths::current_t* out) {
  out->i_cmd_A = current_A_;
}

}  // namespace rths::participants
