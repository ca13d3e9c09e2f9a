#include "participants/marths_run.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "models/marths_coupler.h"
#include "models/marths_records.h"
#include "models/marths_structure.h"
#include "models/newmark_linear.h"
#include "participants/marths_participants.h"

namespace rths::participants {

namespace {
namespace mm = models::marths;

/// The numerical substructure's displacement of `dof` at step k [its unit: m or rad].
double Num(const rths::desired_t& d, int dof) { return d.x_mm[static_cast<std::size_t>(mm::Index(dof))] / 1000.0; }
}  // namespace

MarthsRunScore MarthsScoreOfRun(const io::RunLog& log, const scenario::Scenario& s) {
  if (!s.marths.enabled) throw Error(s.path, "marths.enabled is false: not a maRTHS run");
  const std::int64_t n = log.CompleteSteps();
  const mm::Structures st = mm::BuildStructures(s.marths.files.K_ref, s.marths.files.M_ref,
                                                s.marths.ideal_density_kg_m3, s.marths.dofs);
  const mm::FrameDofs& dofs = st.dofs;
  const auto n_dof = static_cast<std::int32_t>(st.reference.K.rows());
  const models::NewmarkLinear ref = models::MakeNewmarkLinear(st.reference.M, st.reference.C, st.reference.K,
                                                              st.reference.l, s.run.dt_s);
  models::NewmarkLinearState ref_s = models::NewmarkLinearAtRest(ref);
  const std::vector<double> ag = MarthsGroundOf(s, static_cast<std::size_t>(n));
  const signal::MarthsVoltage volts;
  MarthsRunScore out;
  out.steps = n;
  signal::MarthsSignals g;
  g.dt_s = s.run.dt_s;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const rths::desired_t& d = log.desired[i];
    const rths::measured_t& m = log.measured[i];
    const rths::command_t& c = log.command[i];
    if (d.n_act != 2 || m.n_act != 2 || c.n_act != 2 || d.n_dof != n_dof) {
      throw Error(log.source, fmt::format("step {}: the messages do not carry the benchmark's 2 actuators and {} DOFs "
                                          "(desired_t n_act = {}, n_dof = {}; measured_t n_act = {}; command_t "
                                          "n_act = {})",
                                          k, n_dof, d.n_act, d.n_dof, m.n_act, c.n_act));
    }
    models::NewmarkLinearStep(ref, &ref_s, ag[i]);
    const mm::InterfaceMotion est =
        mm::Inverse(s.marths.coupler, {m.y_act_mm[0], m.y_act_mm[1]}, s.marths.inverse);
    g.xa1_t.push_back(d.r_act_mm[0]);
    g.xa2_t.push_back(d.r_act_mm[1]);
    g.xa1_m.push_back(m.y_act_mm[0]);
    g.xa2_m.push_back(m.y_act_mm[1]);
    g.x_hat.push_back(1000.0 * est.x_m);
    g.r_hat.push_back(est.theta_rad);
    mm::AppendNumerical(dofs, d.x_mm[static_cast<std::size_t>(mm::Index(dofs.x()))],
                        [&](int dof) { return Num(d, dof); }, &g);
    mm::AppendReference(ref_s, dofs, &g);
    for (int a = 0; a < 2; ++a) out.max_volts[a] = std::max(out.max_volts[a], std::abs(volts.Volts(a, c.u_act_mm[a])));
  }
  out.j = signal::MarthsCriteriaFrom(g);
  out.realizable = !signal::MarthsSaturated(out.max_volts[0], out.max_volts[1]);
  return out;
}

}  // namespace rths::participants
