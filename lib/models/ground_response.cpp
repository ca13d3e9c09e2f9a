#include "models/ground_response.h"

namespace rths::models {

std::vector<std::vector<double>> GroundResponse(const LinearStructure& structure, double dt_s,
                                                std::span<const double> ground_acc_mm_s2) {
  const CentralDifference cd = CentralDifference::Make(structure, dt_s);
  StructureState st = MakeState(cd);
  const std::size_t n = ground_acc_mm_s2.size();
  std::vector<std::vector<double>> x(static_cast<std::size_t>(cd.dofs()), std::vector<double>(n, 0.0));
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) Advance(cd, &st, ground_acc_mm_s2[k - 1], 0.0);  // x_k from a_g,k-1 (as the integrator)
    for (int i = 0; i < cd.dofs(); ++i) x[static_cast<std::size_t>(i)][k] = st.x[i];
  }
  return x;
}

}  // namespace rths::models
