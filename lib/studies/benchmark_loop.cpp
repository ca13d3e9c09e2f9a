// The benchmark's loop closed as the lockstep testbed or as the reference code closes it
// (studies/benchmark_loop.h, docs/benchmark.md "How the loop is closed").
#include "studies/benchmark_loop.h"

#include <cmath>
#include <filesystem>
#include <memory>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "control/lti_controller.h"
#include "core/error.h"
#include "participants/benchmark_run.h"
#include "models/continuous_structure.h"
#include "models/ground_response.h"
#include "models/rig.h"
#include "models/structure.h"
#include "models/structure_file.h"
#include "signal/history.h"
#include "signal/random.h"

namespace rths::studies {

namespace {

/// Rounds x [mm] to a multiple of q [m] (a Simulink Quantizer on metres); q = 0: unchanged.
double Quantise(double x_mm, double q_m) {
  if (q_m <= 0.0) return x_mm;
  return 1e3 * q_m * std::round(1e-3 * x_mm / q_m);
}

/// The reference code's example-controller subsystem: T and C with converters around them.
struct QuantisedLti {
  control::LtiDesign design;
  control::LtiState state;
  double q_m = 0.0;
  double Step(double target_mm, double y_mm) {
    const double t = Quantise(control::FilterStep(design.reference.discrete, &state.reference,
                                                  Quantise(target_mm, q_m)),
                              q_m);
    return Quantise(control::FilterStep(design.feedback.discrete, &state.feedback, Quantise(t - y_mm, q_m)), q_m);
  }
};

std::string IntegrationName(LoopIntegration i) { return i == LoopIntegration::kRk4 ? "rk4" : "central difference"; }

}  // namespace

std::string LoopOptions::Label() const {
  std::string l = fmt::format("substructure {}, force delay {}, reference {}", IntegrationName(substructure),
                              force_delay_steps, IntegrationName(reference));
  if (quantise_m > 0.0) l += fmt::format(", converters {:.3g} um", 1e6 * quantise_m);
  return l;
}

LoopOptions LockstepLoop() { return {}; }

LoopOptions ReferenceCodeLoop() {
  return {LoopIntegration::kRk4, 1, LoopIntegration::kRk4, std::ldexp(1.0, -18)};
}

namespace {

/// Throws rths::Error naming the key unless the loop `o` can run scenario `s`.
void CheckLoop(const scenario::Scenario& s, const LoopOptions& o) {
  const std::string& where = s.path.empty() ? std::string("<scenario>") : s.path;
  if (s.structure.mode != models::StructureMode::kRths || s.structure.kind != models::StructureKind::kFile ||
      s.structure.reference_file.empty()) {
    throw Error(where + ": structure", "the benchmark loop needs mode \"rths\", kind \"file\" and a reference_file");
  }
  if (s.plant.kind != models::PlantKind::kBenchmark) throw Error(where + ": plant.kind", "needs \"benchmark\"");
  if (o.force_delay_steps < 0 || o.force_delay_steps > 1) throw Error("force_delay_steps", "allowed 0 or 1");
  if (o.quantise_m > 0.0 && s.controller.kind != control::ControllerKind::kLti) {
    throw Error(where + ": controller.kind", "the reference code's converters are modelled for an \"lti\" controller only");
  }
}

/// The reference structure's response x_r,i [mm] per floor over n steps: RK4 on the continuous
/// structure with a_g at the half steps (ground_half), or models::GroundResponse (central difference).
std::vector<std::vector<double>> ReferenceResponse(const models::LinearStructure& ref, LoopIntegration how, double dt,
                                                   const std::vector<double>& ground,
                                                   const std::vector<double>& ground_half) {
  if (how != LoopIntegration::kRk4) return models::GroundResponse(ref, dt, ground);
  return models::GroundResponseRk4(ref, dt, ground_half);
}

}  // namespace

LoopResult RunBenchmarkLoop(const scenario::Scenario& s, const LoopOptions& o) {
  CheckLoop(s, o);
  const double dt = s.run.dt_s;
  const auto n = static_cast<std::size_t>(s.steps());

  const models::LinearStructure st = models::StructureFromScenario(s.structure);
  const models::LinearStructure ref = participants::ReferenceStructure(s, st.dofs());
  const int a = st.actuator_dof;
  const std::vector<double> ground = signal::MakeSignal(s.structure.ground, dt, n);
  std::vector<double> ground_half;  // a_g at k dt/2 (rk4 stages)
  if (o.substructure == LoopIntegration::kRk4 || o.reference == LoopIntegration::kRk4) {
    ground_half = signal::MakeSignal(s.structure.ground, 0.5 * dt, 2 * n + 1);
  }

  const std::unique_ptr<models::Rig> rig = models::MakeRig(s.plant, dt);
  signal::GaussianState noise = signal::MakeGaussian(s.plant.noise_seed);
  const std::unique_ptr<control::TrackingController> law = control::MakeTrackingController(s.controller, dt);
  QuantisedLti quantised;
  if (o.quantise_m > 0.0) quantised = {control::MakeLtiDesign(s.controller.lti, dt), {}, o.quantise_m};
  control::ExtrapolationState past;

  const models::CentralDifference cd = models::CentralDifference::Make(st, dt);
  models::StructureState cd_state = models::MakeState(cd);
  const models::ContinuousStructure cs = models::ContinuousStructure::Make(st);
  models::Rk4Workspace rk_work = models::Rk4Workspace::Make(cs);
  Eigen::VectorXd rk_state = Eigen::VectorXd::Zero(2 * st.dofs());

  signal::BenchmarkSignals rec;
  rec.dt_s = dt;
  rec.actuator_floor = a + 1;
  rec.x_m.resize(n);
  rec.x_t.resize(n);
  rec.x_n.assign(st.dofs(), std::vector<double>(n));
  LoopResult out;
  double f_prev = 0.0;  // f_{k-1}: the Unit Delay's initial condition is 0
  for (std::size_t k = 0; k < n; ++k) {
    const bool rk4 = o.substructure == LoopIntegration::kRk4;
    const Eigen::VectorXd& x = rk4 ? rk_state : cd_state.x;
    const double r = x(a);
    // Readings at t_k, the noise drawn as procs/plant draws it (y then f).
    const double ny = s.plant.noise_y_mm_rms > 0.0 ? s.plant.noise_y_mm_rms * signal::NextGaussian(&noise) : 0.0;
    const double nf = s.plant.noise_f_kN_rms > 0.0 ? s.plant.noise_f_kN_rms * signal::NextGaussian(&noise) : 0.0;
    const double y = rig->MeasuredYMm(ny);
    const double f = rig->f_kN() + nf;
    const control::Derivatives d = control::StepDerivatives(&past, r, dt);
    double u = law->Step(d, {y, f, rig->current_A()}).u_mm;
    if (o.quantise_m > 0.0) u = quantised.Step(r, y);
    if (!std::isfinite(u) || !std::isfinite(r)) throw Error("benchmark loop", fmt::format("diverged at step {}", k));
    out.peak_u_mm = std::max(out.peak_u_mm, std::abs(u));
    rec.x_m[k] = y;
    rec.x_t[k] = r;
    for (int i = 0; i < st.dofs(); ++i) rec.x_n[i][k] = x(i);
    // t_k -> t_{k+1}: the plant with u_k held, the substructure with f_{k-d}.
    rig->Step(u, 0.0);
    const double f_used = o.force_delay_steps == 1 ? f_prev : f;
    if (rk4) {
      const double ag[3] = {ground_half[2 * k], ground_half[2 * k + 1], ground_half[2 * k + 2]};
      models::Rk4Step(cs, &rk_work, &rk_state, dt, ag, f_used);
    } else {
      models::Advance(cd, &cd_state, ground[k], f_used);
    }
    f_prev = f;
  }
  out.steps = static_cast<std::int64_t>(n);

  rec.x_r = ReferenceResponse(ref, o.reference, dt, ground, ground_half);
  out.j = signal::BenchmarkCriteriaFrom(rec);
  return out;
}

}  // namespace rths::studies
