#include "participants/semiactive.h"

#include "core/error.h"
#include "models/structure_file.h"
#include "participants/factory.h"

namespace rths::participants {

Semiactive::Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                       const lockstep::Wiring& wiring, lockstep::Faults faults)
    : StepAnswerer("semiactive", std::move(id), LockstepOf(s), lcm, std::move(faults), wiring.Of("semiactive")),
      f_prev_kN_(0.0) {
  if (s.semiactive.mode == control::SemiactiveMode::kClippedOptimal) {
    const control::ClippedOptimalOptions o{s.semiactive.r_weight, s.semiactive.noise_ratio,
                                           s.semiactive.capacity_kN, s.semiactive.max_current_A};
    clipped_ = std::make_unique<control::ClippedOptimal>(control::DesignClippedOptimal(
        models::StructureFromScenario(s.structure), s.run.dt_s, o));
  } else {
    schedule_.emplace(s.semiactive, s.run.dt_s);
  }
}

bool Semiactive::Compute(std::int64_t k, const lockstep::StepInputs& in, rths::current_t* out) {
  if (clipped_) {
    const rths::desired_t& d = *in.desired;
    const double f_kN = in.measured->f_kN;
    if (d.n_dof != clipped_->design().n) throw Error("semiactive", "desired_t carries the wrong number of DOFs");
    out->i_cmd_A = clipped_->Step(k, d.abs_acc_mm_s2.data(), f_prev_kN_, f_kN);
    out->f_desired_kN = clipped_->desired_force_kN();
    f_prev_kN_ = f_kN;
    return true;
  }
  out->i_cmd_A = schedule_->At(k);
  out->f_desired_kN = 0.0;
  return true;
}

}  // namespace rths::participants
