#include "participants/controller.h"

#include "participants/factory.h"

namespace rths::participants {

Controller::Controller(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                       const lockstep::Wiring& wiring, lockstep::Faults faults)
    : StepAnswerer("controller", std::move(id), LockstepOf(s), lcm, std::move(faults), wiring.Of("controller")),
      law_(control::MakeTrackingController(s.controller, s.run.dt_s)) {}

bool Controller::Compute(std::int64_t, const lockstep::StepInputs& in, rths::command_t* out) {
  const rths::desired_t& d = *in.desired;
  const rths::measured_t& m = *in.measured;
  const control::Derivatives der{d.r_mm,           d.rd_mm_s,         d.rdd_mm_s2,
                                 d.rddd_mm_s3,     d.acc_prev_mm_s2,  d.vel_prev_mm_s};
  const control::Command c = law_->Step(der, {m.y_mm, m.f_kN, m.current_A});
  const double g = faults().command_gain;  // 1 outside fault-injection tests
  out->u_mm = g * c.u_mm;
  out->u_ff_mm = g * c.u_ff_mm;
  out->u_fb_mm = g * c.u_fb_mm;
  out->n_adapt = c.n_adapt;
  out->adapt.assign(c.adapt.begin(), c.adapt.begin() + c.n_adapt);  // capacity kept after the first step
  return true;
}

}  // namespace rths::participants
