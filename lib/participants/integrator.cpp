#include "participants/integrator.h"

#include <filesystem>

#include <fmt/format.h>

#include "core/error.h"
#include "models/structure_file.h"
#include "participants/factory.h"
#include "signal/history.h"

namespace rths::participants {

namespace {
std::string FolderOf(const std::string& path) {
  return std::filesystem::path(path).parent_path().string();
}
}  // namespace

Integrator::Integrator(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                       lockstep::Faults faults)
    : ClockParticipant("integrator", id, TimingOf(s), lcm, std::move(faults)),
      predefined_(s.structure.mode == models::StructureMode::kPredefined),
      dt_s_(s.run.dt_s),
      safety_(s.safety, s.run.dt_s) {
  SetBarrierIncludesNextMeasured(PlantAnswersCommand(s));
  const auto n = static_cast<std::size_t>(id.n_steps);
  const std::string dir = FolderOf(s.path);
  if (predefined_) {
    r_mm_ = signal::MakeSignal(s.structure.desired, dt_s_, n, dir);
    if (s.structure.derivatives == models::Derivatives::kCentral) central_ = control::CentralDerivatives(r_mm_, dt_s_);
    state_.x = Eigen::VectorXd::Zero(1);
    state_.abs_acc_prev = Eigen::VectorXd::Zero(1);
  } else {
    const models::LinearStructure structure = models::StructureFromScenario(s.structure, s.path);
    cd_ = models::CentralDifference::Make(structure, dt_s_);
    state_ = models::MakeState(*cd_);
    dof_ = structure.actuator_dof;
    ground_mm_s2_ = signal::MakeSignal(s.structure.ground, dt_s_, n, dir);
  }
}

void Integrator::ComputeDesired(std::int64_t k, const rths::measured_t* measured_prev,
                                rths::desired_t* out) {
  double r = 0.0, ground = 0.0;
  if (predefined_) {
    r = r_mm_[k];
    state_.x[0] = r;
  } else {
    if (k > 0) {
      if (!measured_prev) throw Error("integrator", "measured_t of the previous step is missing");
      // x_k from x_{k-1}, x_{k-2}, a_g,k-1 and the force measured at k-1 (Eq. 1 with Eqs. 2-3).
      models::Advance(*cd_, &state_, ground_mm_s2_[k - 1], measured_prev->f_kN);
    }
    r = state_.x[dof_];
    ground = ground_mm_s2_[k];
  }
  control::Derivatives d = control::StepDerivatives(&extrapolation_, r, dt_s_);
  if (central_) d = central_->At(r_mm_, static_cast<std::size_t>(k));

  out->r_mm = r;
  out->rd_mm_s = d.rd;
  out->rdd_mm_s2 = d.rdd;
  out->rddd_mm_s3 = d.rddd;
  out->acc_prev_mm_s2 = d.acc_prev;
  out->vel_prev_mm_s = d.vel_prev;
  out->ground_acc_mm_s2 = ground;
  const int n = static_cast<int>(state_.x.size());
  if (out->n_dof != n) {  // sized once, on the first step
    out->n_dof = n;
    out->x_mm.resize(n);
    out->abs_acc_mm_s2.resize(n);
  }
  for (int j = 0; j < n; ++j) {
    out->x_mm[j] = state_.x[j];
    out->abs_acc_mm_s2[j] = (predefined_ || k == 0) ? 0.0 : state_.abs_acc_prev[j];
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
