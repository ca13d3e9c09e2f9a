#include "studies/marths_loop.h"

#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "control/mimo_feedforward.h"
#include "control/tracking_controller.h"
#include "core/error.h"
#include "models/marths_records.h"
#include "models/marths_rig.h"
#include "models/marths_structure.h"
#include "models/newmark_linear.h"

namespace rths::studies {

namespace mm = models::marths;

namespace {

/// The S5_Evaluation.m records, reserved for n samples.
signal::MarthsSignals ReservedSignals(std::size_t n, double dt_s) {
  signal::MarthsSignals s;
  s.dt_s = dt_s;
  for (auto* v : {&s.xa1_t, &s.xa2_t, &s.xa1_m, &s.xa2_m, &s.x_hat, &s.r_hat, &s.x_num, &s.r_num,
                  &s.x_ref, &s.r_ref, &s.x2_num, &s.r2_num, &s.x3_num, &s.r3_num, &s.x2_ref, &s.r2_ref,
                  &s.x3_ref, &s.r3_ref}) {
    v->reserve(n);
  }
  return s;
}

double U(const models::NewmarkLinearState& s, int dof) { return s.U(mm::Index(dof)); }

}  // namespace

MarthsLoopResult RunMarthsLoop(const MarthsLoopConfig& c) {
  const std::size_t n = c.ag_m_s2.size();
  if (n < 2) throw Error("maRTHS loop", "the ground motion has fewer than 2 samples");
  const mm::Structures st = mm::BuildStructures(c.K_ref, c.M_ref, c.ideal_density_kg_m3, c.dofs);
  const mm::MarthsSubstructure sub{models::MakeNewmarkLinear(st.numerical.M, st.numerical.C, st.numerical.K,
                                                             st.numerical.l, c.dt_s),
                                   c.rig.geometry, st.dofs};
  const models::NewmarkLinear ref = models::MakeNewmarkLinear(st.reference.M, st.reference.C, st.reference.K,
                                                              st.reference.l, c.dt_s);
  const mm::MarthsRig rig = mm::MakeMarthsRig(c.plant, c.dt_s, c.rig);

  models::NewmarkLinearState num_s = models::NewmarkLinearAtRest(sub.numerical);
  models::NewmarkLinearState ref_s = models::NewmarkLinearAtRest(ref);
  mm::MarthsRigState rig_s = mm::MarthsRigAtRest(rig);
  control::MarthsCompensators compensators(c.compensators, c.dt_s);

  MarthsLoopResult r;
  r.signals = ReservedSignals(n, c.dt_s);
  signal::MarthsSignals& g = r.signals;
  for (std::size_t k = 0; k < n; ++k) {
    const double ag = c.ag_m_s2[k];
    const mm::RigReading reading = mm::RigRead(rig, &rig_s);   // strokes and forces at t_k
    const Eigen::Vector2d& y = reading.y_mm;
    const mm::InterfaceMotion& est = reading.estimate;
    const mm::SubstructureOutput out = mm::SubstructureStep(sub, &num_s, ag, reading.forces);
    const mm::ActuatorPair& t = out.targets;
    const Eigen::Vector2d u = compensators.Step(Eigen::Vector2d(t.a1_mm, t.a2_mm), y);
    if (!u.allFinite() || !y.allFinite()) {
      throw Error("maRTHS loop", fmt::format("diverged at sample {} (t = {:.4f} s)", k, k * c.dt_s));
    }
    mm::RigStep(rig, &rig_s, u);
    models::NewmarkLinearStep(ref, &ref_s, ag);
    for (int i = 0; i < 2; ++i) r.max_volts[i] = std::max(r.max_volts[i], std::abs(c.volts.Volts(i, u(i))));

    g.xa1_t.push_back(t.a1_mm);
    g.xa2_t.push_back(t.a2_mm);
    g.xa1_m.push_back(y(0));
    g.xa2_m.push_back(y(1));
    g.x_hat.push_back(1000.0 * est.x_m);
    g.r_hat.push_back(est.theta_rad);
    mm::AppendNumerical(st.dofs, 1000.0 * U(num_s, st.dofs.x()), [&](int dof) { return U(num_s, dof); }, &g);
    mm::AppendReference(ref_s, st.dofs, &g);
  }
  r.saturated = signal::MarthsSaturated(r.max_volts[0], r.max_volts[1]);
  r.j = signal::MarthsCriteriaFrom(g);
  return r;
}

}  // namespace rths::studies
