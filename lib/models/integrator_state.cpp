#include "models/integrator_state.h"

namespace rths::models {

IntegratorState MakeIntegratorState(const NonlinearBuilding& b) {
  const Eigen::Index n = b.dofs();
  IntegratorState s;
  s.x = s.x_prev = s.v = s.a = s.x_corr = s.v_pred = s.q_prev = s.w1 = s.w2 = s.w3 = s.w4 =
      Eigen::VectorXd::Zero(n);
  s.J = Eigen::MatrixXd::Zero(n, n);
  s.lu = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  s.building = MakeBuildingState(b);
  return s;
}

}  // namespace rths::models
