#include "participants/integrator.h"

#include <fmt/format.h>

#include "core/error.h"
#include "models/structure_file.h"
#include "participants/factory.h"
#include "signal/history.h"

namespace rths::participants {

namespace {
/// The scenario's numerical substructure, its histories made for `n` steps from the data the scenario
/// loader read (never the files themselves).
models::NumericalSubstructure MakeSubstructure(const scenario::Scenario& s, std::size_t n) {
  if (s.structure.mode == models::StructureMode::kPredefined) {
    return models::NumericalSubstructure::Predefined(signal::MakeSignal(s.structure.desired, s.run.dt_s, n));
  }
  if (s.structure.Stepped()) {
    return models::NumericalSubstructure::Stepped(models::SteppedIntegratorFromScenario(s.structure, s.run.dt_s),
                                                  signal::MakeSignal(s.structure.ground, s.run.dt_s, n));
  }
  const models::LinearStructure structure = models::StructureFromScenario(s.structure);
  if (s.structure.integrator.kind == models::IntegratorKind::kRk4UnitDelay) {
    return models::NumericalSubstructure::Rk4UnitDelay(structure, s.run.dt_s,
                                                       signal::MakeSignal(s.structure.ground, s.run.dt_s, n),
                                                       signal::MakeSignal(s.structure.ground, 0.5 * s.run.dt_s, 2 * n + 1));
  }
  auto m = models::NumericalSubstructure::Integrated(structure, s.run.dt_s, {});
  m.ground_mm_s2 = signal::MakeSignal(s.structure.ground, s.run.dt_s, n);  // after the structure's checks
  return m;
}
}  // namespace

Integrator::Integrator(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                       const lockstep::Wiring& wiring, lockstep::Faults faults)
    : ClockParticipant("integrator", id, LockstepOf(s), lcm, wiring, std::move(faults)),
      dt_s_(s.run.dt_s),
      substructure_(MakeSubstructure(s, static_cast<std::size_t>(id.n_steps))),
      state_(models::MakeState(substructure_)),
      safety_(s.safety, s.run.dt_s) {
  if (substructure_.predefined() && s.structure.derivatives == models::Derivatives::kCentral) {
    central_ = control::CentralDerivatives(substructure_.r_mm, dt_s_);
  }
  if (s.safety.enabled) SetLiveLimits({s.safety.stroke_mm, s.safety.force_kN, s.safety.max_error_mm});
}

void Integrator::ComputeDesired(std::int64_t k, const rths::measured_t* measured_prev,
                                rths::desired_t* out) {
  const bool predefined = substructure_.predefined();
  if (!predefined && k > 0 && !measured_prev) throw Error("integrator", "measured_t of the previous step is missing");
  // x_k from x_{k-1}, x_{k-2}, a_g,k-1 and the force measured at k-1 (Eq. 1 with Eqs. 2-3).
  const double r = models::Step(substructure_, &state_, k, k > 0 && measured_prev ? measured_prev->f_kN : 0.0);
  const double ground = models::GroundAt(substructure_, k);
  control::Derivatives d = control::StepDerivatives(&extrapolation_, r, dt_s_);
  if (central_) d = central_->At(substructure_.r_mm, static_cast<std::size_t>(k));

  out->r_mm = r;
  out->rd_mm_s = d.rd;
  out->rdd_mm_s2 = d.rdd;
  out->rddd_mm_s3 = d.rddd;
  out->acc_prev_mm_s2 = d.acc_prev;
  out->vel_prev_mm_s = d.vel_prev;
  out->ground_acc_mm_s2 = ground;
  const models::StructureState& st = state_.structure;
  const int n = static_cast<int>(st.x.size());
  if (out->n_dof != n) {  // sized once, on the first step
    out->n_dof = n;
    out->x_mm.resize(n);
    out->abs_acc_mm_s2.resize(n);
  }
  for (int j = 0; j < n; ++j) {
    out->x_mm[j] = st.x[j];
    out->abs_acc_mm_s2[j] = (predefined || k == 0) ? 0.0 : st.abs_acc_prev[j];
  }
}

}  // namespace rths::participants

namespace rths::participants {

std::string_view Integrator::CheckCommitted(std::int64_t k, const rths::desired_t& desired,
                                            const rths::measured_t& measured,
                                            const rths::command_t& command) {
  return safety_.Check(k, desired.r_mm, command.u_mm, measured.y_mm, measured.f_kN);
}

}  // namespace rths::participants
