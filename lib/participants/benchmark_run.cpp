#include "participants/benchmark_run.h"

#include <fmt/format.h>

#include "core/error.h"
#include "models/continuous_structure.h"
#include "models/ground_response.h"
#include "models/structure_file.h"
#include "signal/history.h"

namespace rths::participants {

models::LinearStructure ReferenceStructure(const scenario::Scenario& s, int run_dofs) {
  const std::string where = fmt::format("{}: structure.reference_file", s.path.empty() ? "<scenario text>" : s.path);
  const models::StructureConfig& st = s.structure;
  if (st.reference_file.empty()) throw Error(where, "not set: the criteria need a reference structure");
  const models::StructureMatrices& m = st.reference;  // read by the scenario loader
  if (m.M.rows() == 0) throw Error(where, fmt::format("{}: not read (scenario::LoadScenario reads it)", st.reference_file));
  if (m.M.rows() != run_dofs)
    throw Error(where, fmt::format("{} has {} DOFs but the run's structure has {}: they must match", st.reference_file,
                                   m.M.rows(), run_dofs));
  if (st.actuator_dof < 1 || st.actuator_dof > run_dofs)
    throw Error(fmt::format("{}: structure.actuator_dof", s.path),
                fmt::format("{} is out of range [1, {}]", st.actuator_dof, run_dofs));
  models::LinearStructure ref = models::LinearStructure::Make(m.M, m.C, m.K, st.actuator_dof - 1, 1.0);
  if (m.iota.size()) ref.iota = m.iota;
  return ref;
}

signal::BenchmarkSignals BenchmarkSignalsFromRun(const io::RunSignals& signals, const scenario::Scenario& s) {
  int dofs = 0;
  while (signals.Find(fmt::format("x{}_mm", dofs + 1))) ++dofs;
  if (dofs == 0) throw Error("benchmark criteria", "the run's signals have no structure displacement (x1_mm)");
  const models::LinearStructure ref = ReferenceStructure(s, dofs);
  signal::BenchmarkSignals b;
  b.dt_s = signals.dt_s;
  b.actuator_floor = s.structure.actuator_dof;
  b.x_m = signals.At("y_mm").values;
  b.x_t = signals.At("r_mm").values;
  for (int i = 1; i <= dofs; ++i) b.x_n.push_back(signals.At(fmt::format("x{}_mm", i)).values);
  try {
    if (s.structure.integrator.kind == models::IntegratorKind::kRk4UnitDelay) {
      // As the reference code scores it: the reference integrated continuously (lsim), a_g at the
      // half steps from the scenario's record.
      const std::size_t n = b.x_m.size();
      b.x_r = models::GroundResponseRk4(ref, signals.dt_s, signal::MakeSignal(s.structure.ground, 0.5 * signals.dt_s, 2 * n + 1));
    } else {
      b.x_r = models::GroundResponse(ref, signals.dt_s, signals.At("ground_acc_mm_s2").values);
    }
  } catch (const Error& e) {
    throw Error(fmt::format("{}: structure.reference_file", s.path), e.what());
  }
  return b;
}

signal::BenchmarkCriteria BenchmarkCriteriaFromRun(const io::RunSignals& signals, const scenario::Scenario& s) {
  return signal::BenchmarkCriteriaFrom(BenchmarkSignalsFromRun(signals, s));
}

signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const io::RunLog& log, const scenario::Scenario& s) {
  return BenchmarkCriteriaFromRun(io::SignalsFromRunLog(log, s.run.dt_s), s);
}

signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const std::string& log_path, const scenario::Scenario& s) {
  return BenchmarkCriteriaOfRun(io::ReadRunLog(log_path), s);
}

}  // namespace rths::participants
