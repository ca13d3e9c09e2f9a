#include "models/numerical_substructure.h"

#include <utility>

#include "core/error.h"

namespace rths::models {

NumericalSubstructure NumericalSubstructure::Predefined(std::vector<double> r_mm) {
  NumericalSubstructure m;
  m.r_mm = std::move(r_mm);
  return m;
}

NumericalSubstructure NumericalSubstructure::Integrated(const LinearStructure& structure, double dt_s,
                                                        std::vector<double> ground_mm_s2) {
  NumericalSubstructure m;
  m.cd = CentralDifference::Make(structure, dt_s);
  m.dt_s = dt_s;
  m.dof = structure.actuator_dof;
  m.ground_mm_s2 = std::move(ground_mm_s2);
  return m;
}

NumericalSubstructure NumericalSubstructure::Rk4UnitDelay(const LinearStructure& structure, double dt_s,
                                                          std::vector<double> ground_mm_s2,
                                                          std::vector<double> ground_half_mm_s2) {
  if (ground_half_mm_s2.size() != 2 * ground_mm_s2.size() + 1)
    throw Error("rk4_unit_delay", "needs a_g at the half steps: 2N + 1 values for N steps");
  NumericalSubstructure m = Integrated(structure, dt_s, std::move(ground_mm_s2));
  m.rk4 = ContinuousStructure::Make(structure);
  m.ground_half_mm_s2 = std::move(ground_half_mm_s2);
  return m;
}

NumericalSubstructure NumericalSubstructure::Stepped(const StructureIntegrator& integrator,
                                                     std::vector<double> ground_mm_s2) {
  NumericalSubstructure m;
  m.stepped = integrator;
  m.dt_s = integrator.dt_s;
  m.dof = integrator.building.actuator_dof;
  m.ground_mm_s2 = std::move(ground_mm_s2);
  return m;
}

SubstructureState MakeState(const NumericalSubstructure& m) {
  SubstructureState s;
  if (m.stepped) {
    const int n = m.stepped->building.dofs();
    s.stepped = MakeIntegratorState(m.stepped->building);
    s.structure.x = s.structure.x_prev = s.structure.vel_prev = s.structure.acc_prev = s.structure.abs_acc_prev =
        Eigen::VectorXd::Zero(n);
    return s;
  }
  if (m.cd) {
    s.structure = MakeState(*m.cd);
  } else {
    s.structure.x = Eigen::VectorXd::Zero(1);
    s.structure.abs_acc_prev = Eigen::VectorXd::Zero(1);
  }
  if (m.rk4) {
    s.z = Eigen::VectorXd::Zero(2 * m.rk4->n);
    s.rk = Rk4Workspace::Make(*m.rk4);
  }
  return s;
}

namespace {

/// rk4_unit_delay's step k > 0: z_{k-1} -> z_k with f_{k-2} held, then the outputs.
void StepRk4(const NumericalSubstructure& m, SubstructureState* s, std::int64_t k, double f_prev_kN) {
  const auto j = static_cast<std::size_t>(2 * (k - 1));
  const double ag[3] = {m.ground_half_mm_s2[j], m.ground_half_mm_s2[j + 1], m.ground_half_mm_s2[j + 2]};
  s->structure.vel_prev = s->z.tail(m.rk4->n);  // x'_{k-1}
  Rk4Step(*m.rk4, &s->rk, &s->z, m.dt_s, ag, s->f_delayed_kN);
  s->f_delayed_kN = f_prev_kN;
  const int n = m.rk4->n;
  StructureState& out = s->structure;
  out.k = k;
  out.x_prev = out.x;
  out.x = s->z.head(n);
  // The first stage is the rate at t_{k-1}: its lower half the relative accelerations there.
  out.acc_prev = s->rk.k1.tail(n);
  out.abs_acc_prev = out.acc_prev + m.cd->iota * m.ground_mm_s2[static_cast<std::size_t>(k - 1)];
}

/// Stepped's step k > 0: the method's k-1 -> k with f_{k-1}, then the outputs.
void StepStepped(const NumericalSubstructure& m, SubstructureState* s, std::int64_t k, double f_prev_kN) {
  const double ag_prev = m.ground_mm_s2[static_cast<std::size_t>(k - 1)];
  Advance(*m.stepped, &s->stepped, ag_prev, m.ground_mm_s2[static_cast<std::size_t>(k)], f_prev_kN);
  StructureState& out = s->structure;
  out.k = k;
  out.x_prev = out.x;
  out.x = s->stepped.x;
  out.vel_prev = s->stepped.v;
  out.acc_prev = s->stepped.a;
  out.abs_acc_prev = s->stepped.a + m.stepped->building.iota * ag_prev;
}

}  // namespace

double Step(const NumericalSubstructure& m, SubstructureState* s, std::int64_t k, double f_prev_kN) {
  if (m.predefined()) {
    const double r = m.r_mm[static_cast<std::size_t>(k)];
    s->structure.x[0] = r;
    return r;
  }
  if (k > 0) {
    if (m.stepped) {
      StepStepped(m, s, k, f_prev_kN);
    } else if (m.rk4) {
      StepRk4(m, s, k, f_prev_kN);
    } else {
      Advance(*m.cd, &s->structure, m.ground_mm_s2[static_cast<std::size_t>(k - 1)], f_prev_kN);
    }
  }
  return s->structure.x[m.dof];
}

}  // namespace rths::models
