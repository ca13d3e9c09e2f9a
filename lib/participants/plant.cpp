#include "participants/plant.h"

#include "core/error.h"
#include "participants/factory.h"

namespace rths::participants {

Plant::Plant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
             lockstep::Faults faults)
    : StepAnswerer("plant", std::move(id), LockstepOf(s), lcm, std::move(faults), wiring.Of("plant")),
      rig_(models::MakeRig(s.plant, s.run.dt_s)),
      noise_y_mm_(s.plant.noise_y_mm_rms),
      noise_f_kN_(s.plant.noise_f_kN_rms),
      noise_(signal::MakeGaussian(s.plant.noise_seed)) {
  if (rig_->TracksDesired() != (wiring.Of("plant").row->variant == lockstep::kIdealVariant)) {
    throw Error("plant", "the run's wiring does not match plant.kind (\"ideal\" answers desired_t k)");
  }
}

bool Plant::Compute(std::int64_t k, const lockstep::StepInputs& in, rths::measured_t* out) {
  if (rig_->TracksDesired()) {
    // plant.kind = "ideal" (docs/lockstep.md, footnote): measured_t k from desired_t k (r_k) and
    // current_t k-1; the command is logged but not used.
    if (k == 0) {
      rig_->StartAt(in.desired->r_mm);  // at rest at r_0 (0 A)
    } else {
      rig_->Step(in.desired->r_mm, in.current->i_cmd_A);  // x(t) from r_{k-1} to r_k over [t_{k-1}, t_k], i_{k-1}
    }
  } else if (k > 0) {
    rig_->Step(in.command->u_mm, in.current->i_cmd_A);  // hold u_{k-1}, i_{k-1} over [t_{k-1}, t_k)
  }  // k = 0: at rest; no current has been commanded yet (0 A)
  // Noise is drawn once per sample, in step order, so a seed gives the same readings every run.
  const double ny = noise_y_mm_ > 0.0 ? noise_y_mm_ * signal::NextGaussian(&noise_) : 0.0;
  const double nf = noise_f_kN_ > 0.0 ? noise_f_kN_ * signal::NextGaussian(&noise_) : 0.0;
  out->y_mm = rig_->MeasuredYMm(ny);  // y_mm() + ny; "benchmark" with its DAQ: noise before the A/D
  out->f_kN = rig_->f_kN() + nf;
  out->current_A = rig_->current_A();  // effective current at t_k
  return true;
}

}  // namespace rths::participants
