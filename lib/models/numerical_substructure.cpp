#include "models/numerical_substructure.h"

#include <utility>

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
  m.dof = structure.actuator_dof;
  m.ground_mm_s2 = std::move(ground_mm_s2);
  return m;
}

StructureState MakeState(const NumericalSubstructure& m) {
  if (m.cd) return MakeState(*m.cd);
  StructureState s;
  s.x = Eigen::VectorXd::Zero(1);
  s.abs_acc_prev = Eigen::VectorXd::Zero(1);
  return s;
}

double Step(const NumericalSubstructure& m, StructureState* s, std::int64_t k, double f_prev_kN) {
  if (m.predefined()) {
    const double r = m.r_mm[static_cast<std::size_t>(k)];
    s->x[0] = r;
    return r;
  }
  if (k > 0) Advance(*m.cd, s, m.ground_mm_s2[static_cast<std::size_t>(k - 1)], f_prev_kN);
  return s->x[m.dof];
}

}  // namespace rths::models
