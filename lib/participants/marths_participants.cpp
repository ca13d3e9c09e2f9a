#include "participants/marths_participants.h"

#include <fmt/format.h>

#include "core/error.h"
#include "models/marths_structure.h"
#include "participants/factory.h"
#include "signal/history.h"
#include "signal/random.h"

namespace rths::participants {

namespace mm = models::marths;

models::marths::PlantZpk MarthsPlantOf(const scenario::Scenario& s) {
  mm::PlantZpk p = mm::NominalPlantZpk();
  signal::GaussianState g = signal::MakeGaussian(static_cast<std::uint64_t>(s.marths.plant_seed));
  for (int i = 0; i < s.marths.perturbed_plant; ++i) p = mm::PerturbedPlantZpk(mm::NominalPlantZpk(), &g);
  return p;
}

models::marths::RigOptions MarthsRigOptionsOf(const scenario::Scenario& s) {
  mm::RigOptions o;
  o.noise_mm = s.plant.noise_y_mm_rms;
  o.identical_noise = s.marths.identical_noise;
  o.noise_seed = static_cast<std::uint64_t>(s.marths.noise_seed);
  o.geometry = s.marths.coupler;
  o.inverse = s.marths.inverse;
  o.force_delay_steps = s.marths.force_delay_steps;
  o.derivatives_from_rest = s.marths.derivatives_from_rest;
  return o;
}

std::vector<double> MarthsGroundOf(const scenario::Scenario& s, std::size_t n) {
  return signal::ResampleHistory(s.marths.ground, 0.0, s.marths.ground_scale, s.run.dt_s, n, 0.0);
}

control::MarthsCompensatorSpec MarthsCompensatorsOf(const scenario::Scenario& s) {
  control::MarthsCompensatorSpec c;
  c.kind = s.marths.compensator;
  const mm::RodeacInitialParameters& p = s.marths.files.rodeac;
  for (int i = 0; i < 2; ++i) {
    c.rodeac[i] = control::MakeRodeacDesign(p.theta0[i], p.P0[i], 1.0 / s.run.dt_s);
    c.per_actuator[i] = s.controller;
  }
  c.per_actuator[0].model = s.marths.model_1;
  c.per_actuator[1].model = s.marths.model_2;
  return c;
}

namespace {

/// The numerical substructure of the scenario's matrices, at run.dt_s.
mm::MarthsSubstructure SubstructureOf(const scenario::Scenario& s) {
  const mm::Structures st = mm::BuildStructures(s.marths.files.K_ref, s.marths.files.M_ref,
                                                s.marths.ideal_density_kg_m3, s.marths.dofs);
  return {models::MakeNewmarkLinear(st.numerical.M, st.numerical.C, st.numerical.K, st.numerical.l, s.run.dt_s),
          s.marths.coupler, st.dofs};
}

/// Sizes a message's array once (the first step), so that later steps only write into it.
void Size(std::vector<double>* v, std::int32_t* n, int want) {
  if (*n == want) return;
  *n = want;
  v->resize(static_cast<std::size_t>(want));
}

void RequireActuators(const char* who, const char* what, std::int32_t n) {
  if (n != 2) throw Error(who, fmt::format("{} carries {} actuators' values, not the benchmark's 2", what, n));
}

}  // namespace

MarthsIntegrator::MarthsIntegrator(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                                   const lockstep::Wiring& wiring, lockstep::Faults faults)
    : ClockParticipant("integrator", id, LockstepOf(s), lcm, wiring, std::move(faults)),
      dt_s_(s.run.dt_s),
      sub_(SubstructureOf(s)),
      state_(models::NewmarkLinearAtRest(sub_.numerical)),
      ag_m_s2_(MarthsGroundOf(s, static_cast<std::size_t>(id.n_steps))),
      safety_(s.safety, s.run.dt_s, 2) {
  if (wiring.Clock().row->variant != lockstep::kSameSampleVariant) {
    throw Error("integrator", "the maRTHS loop needs the integrator's \"same_sample\" row (desired_t k from measured_t k)");
  }
  if (s.safety.enabled) SetLiveLimits({s.safety.stroke_mm, s.safety.force_kN, s.safety.max_error_mm});
}

void MarthsIntegrator::ComputeDesired(std::int64_t k, const rths::measured_t* measured, rths::desired_t* out) {
  if (!measured) throw Error("integrator", fmt::format("measured_t {} is missing", k));
  if (measured->n_iface != 3) {
    throw Error("integrator", fmt::format("measured_t {} carries {} interface forces, not the benchmark's 3", k,
                                          measured->n_iface));
  }
  const mm::InterfaceForces f{measured->f_iface[0], measured->f_iface[1], measured->f_iface[2]};
  const double ag = ag_m_s2_[static_cast<std::size_t>(k)];
  const mm::SubstructureOutput o = mm::SubstructureStep(sub_, &state_, ag, f);
  const control::Derivatives d = control::StepDerivatives(&extrapolation_, o.targets.a1_mm, dt_s_);
  out->r_mm = o.targets.a1_mm;
  out->rd_mm_s = d.rd;
  out->rdd_mm_s2 = d.rdd;
  out->rddd_mm_s3 = d.rddd;
  out->acc_prev_mm_s2 = d.acc_prev;
  out->vel_prev_mm_s = d.vel_prev;
  out->ground_acc_mm_s2 = 1000.0 * ag;
  const int n = static_cast<int>(state_.U.size());
  if (out->n_dof != n) {
    out->n_dof = n;
    out->x_mm.resize(static_cast<std::size_t>(n));
    out->abs_acc_mm_s2.assign(static_cast<std::size_t>(n), 0.0);
  }
  for (int j = 0; j < n; ++j) out->x_mm[static_cast<std::size_t>(j)] = 1000.0 * state_.U(j);
  Size(&out->r_act_mm, &out->n_act, 2);
  out->r_act_mm[0] = o.targets.a1_mm;
  out->r_act_mm[1] = o.targets.a2_mm;
}

std::string_view MarthsIntegrator::CheckCommitted(std::int64_t k, const rths::desired_t& desired,
                                                  const rths::measured_t& measured, const rths::command_t& command) {
  RequireActuators("integrator", "desired_t", desired.n_act);
  RequireActuators("integrator", "command_t", command.n_act);
  RequireActuators("integrator", "measured_t", measured.n_act);
  return safety_.CheckActuators(k, desired.r_act_mm.data(), command.u_act_mm.data(), measured.y_act_mm.data(),
                                measured.f_kN);
}

MarthsPlant::MarthsPlant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                         const lockstep::Wiring& wiring, lockstep::Faults faults)
    : StepAnswerer("plant", std::move(id), LockstepOf(s), lcm, std::move(faults), wiring.Of("plant")),
      rig_(mm::MakeMarthsRig(MarthsPlantOf(s), s.run.dt_s, MarthsRigOptionsOf(s))),
      state_(mm::MarthsRigAtRest(rig_)) {}

bool MarthsPlant::Compute(std::int64_t k, const lockstep::StepInputs& in, rths::measured_t* out) {
  if (k > 0) {  // u_{k-1} held over [t_{k-1}, t_k)
    RequireActuators("plant", "command_t", in.command->n_act);
    mm::RigStep(rig_, &state_, Eigen::Vector2d(in.command->u_act_mm[0], in.command->u_act_mm[1]));
  }
  const mm::RigReading r = mm::RigRead(rig_, &state_);
  out->y_mm = r.y_mm(0);
  out->f_kN = 0.0;
  out->current_A = 0.0;
  Size(&out->y_act_mm, &out->n_act, 2);
  out->y_act_mm[0] = r.y_mm(0);
  out->y_act_mm[1] = r.y_mm(1);
  Size(&out->f_iface, &out->n_iface, 3);
  out->f_iface[0] = r.forces.F27_N;
  out->f_iface[1] = r.forces.M21_N_m;
  out->f_iface[2] = r.forces.M29_N_m;
  return true;
}

MarthsController::MarthsController(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                                   const lockstep::Wiring& wiring, lockstep::Faults faults)
    : StepAnswerer("controller", std::move(id), LockstepOf(s), lcm, std::move(faults), wiring.Of("controller")),
      compensators_(MarthsCompensatorsOf(s), s.run.dt_s) {}

bool MarthsController::Compute(std::int64_t k, const lockstep::StepInputs& in, rths::command_t* out) {
  RequireActuators("controller", "desired_t", in.desired->n_act);
  RequireActuators("controller", "measured_t", in.measured->n_act);
  const Eigen::Vector2d t(in.desired->r_act_mm[0], in.desired->r_act_mm[1]);
  const Eigen::Vector2d y(in.measured->y_act_mm[0], in.measured->y_act_mm[1]);
  const Eigen::Vector2d u = compensators_.Step(t, y);
  if (!u.allFinite() || !y.allFinite()) {
    throw Error("controller", fmt::format("the maRTHS loop diverged at step {} (t = {:.4f} s)", k,
                                          static_cast<double>(k) * id_.dt_s));
  }
  const control::Command c1 = compensators_.Last(0);
  out->u_mm = u(0);
  out->u_ff_mm = c1.u_ff_mm;
  out->u_fb_mm = c1.u_fb_mm;
  out->n_adapt = 0;
  out->adapt.clear();
  Size(&out->u_act_mm, &out->n_act, 2);
  out->u_act_mm[0] = u(0);
  out->u_act_mm[1] = u(1);
  return true;
}

}  // namespace rths::participants
