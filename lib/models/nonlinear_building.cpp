#include "models/nonlinear_building.h"

#include <cmath>
#include <string>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

Eigen::MatrixXd MassMatrix(const std::vector<double>& m_kg) {
  const int n = static_cast<int>(m_kg.size());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) M(i, i) = m_kg[i] * 1e-6;
  return M;
}

Eigen::MatrixXd StoryStiffnessMatrix(const std::vector<double>& k_kN_per_mm) {
  const int n = static_cast<int>(k_kN_per_mm.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    const double k = k_kN_per_mm[i];  // story i+1, below floor i+1
    K(i, i) += k;
    if (i > 0) {
      K(i - 1, i - 1) += k;
      K(i - 1, i) -= k;
      K(i, i - 1) -= k;
    }
  }
  return K;
}

Eigen::MatrixXd InitialStiffness(const std::vector<SpringParams>& springs) {
  std::vector<double> k;
  for (const SpringParams& p : springs) k.push_back(p.k_kN_per_mm);
  return StoryStiffnessMatrix(k);
}

Eigen::MatrixXd RayleighDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, int mode_i,
                                      double zeta_i, int mode_j, double zeta_j) {
  const int n = static_cast<int>(M.rows());
  for (int m : {mode_i, mode_j})
    if (m < 1 || m > n)
      throw Error("rayleigh modes", fmt::format("must be in [1, {}] (got {})", n, m));
  for (double z : {zeta_i, zeta_j})
    if (!(z >= 0.0 && z < 1.0))
      throw Error("rayleigh damping ratios", fmt::format("must be in [0, 1) (got {})", z));
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M, Eigen::EigenvaluesOnly);
  const double wi = std::sqrt(std::max(0.0, eig.eigenvalues()(mode_i - 1)));
  const double wj = std::sqrt(std::max(0.0, eig.eigenvalues()(mode_j - 1)));
  if (!(std::abs(wi - wj) > 1e-12 * std::max(wi, wj)))
    throw Error("rayleigh modes", fmt::format("modes {} and {} have one frequency", mode_i, mode_j));
  // [1/(2wi) wi/2; 1/(2wj) wj/2] [a0; a1] = [zi; zj]
  const double det = wj / (4.0 * wi) - wi / (4.0 * wj);
  const double a0 = (zeta_i * wj / 2.0 - zeta_j * wi / 2.0) / det;
  const double a1 = (zeta_j / (2.0 * wi) - zeta_i / (2.0 * wj)) / det;
  return a0 * M + a1 * K;
}

NonlinearBuilding NonlinearBuilding::Make(const std::vector<double>& m_kg,
                                          const std::vector<SpringParams>& springs,
                                          const Eigen::MatrixXd& C, int actuator_dof,
                                          double specimen_count) {
  const int n = static_cast<int>(m_kg.size());
  if (n == 0 || springs.size() != m_kg.size())
    throw Error("springs", fmt::format("one spring per floor mass is needed (got {} masses, {} springs)",
                                       m_kg.size(), springs.size()));
  for (int i = 0; i < n; ++i)
    if (!(m_kg[i] > 0.0 && m_kg[i] <= 1e9))
      throw Error(fmt::format("floor_masses_kg[{}]", i), fmt::format("must be in (0, 1e9] (got {})", m_kg[i]));
  NonlinearBuilding b;
  for (int i = 0; i < n; ++i) {
    try {
      springs[i].Validate();
    } catch (const Error& e) {
      throw Error(fmt::format("springs[{}]: {}", i, e.where()), e.problem());
    }
    b.all_linear = b.all_linear && springs[i].kind == SpringKind::kLinear;
  }
  if (C.rows() != n || C.cols() != n || !C.allFinite())
    throw Error("C", fmt::format("must be a finite {}x{} matrix (got {}x{})", n, n, C.rows(), C.cols()));
  const LinearStructure lin = LinearStructure::Make(MassMatrix(m_kg), C, InitialStiffness(springs),
                                                    actuator_dof, specimen_count);
  b.M = lin.M, b.C = lin.C, b.K0 = lin.K;
  b.iota = lin.iota;
  b.specimen_dir = lin.specimen_dir;
  b.actuator_dof = lin.actuator_dof;
  b.springs = springs;
  return b;
}

LinearStructure NonlinearBuilding::Initial() const {
  LinearStructure s;
  s.M = M, s.C = C, s.K = K0;
  s.iota = iota;
  s.specimen_dir = specimen_dir;
  s.actuator_dof = actuator_dof;
  return s;
}

double BuildingState::HystereticEnergy() const {
  double e = 0.0;
  for (const SpringState& s : committed) e += s.energy_kN_mm;
  return e;
}

BuildingState MakeBuildingState(const NonlinearBuilding& b) {
  const std::size_t n = b.springs.size();
  BuildingState s;
  s.committed.assign(n, SpringState{});
  s.trial.assign(n, SpringState{});
  s.story_force_kN.assign(n, 0.0);
  s.story_tangent_kN_per_mm.assign(n, 0.0);
  s.restoring_kN = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  return s;
}

void Evaluate(const NonlinearBuilding& b, const Eigen::VectorXd& x, BuildingState* s) {
  const int n = b.dofs();
  for (int i = 0; i < n; ++i) {
    const double u = x(i) - (i > 0 ? x(i - 1) : 0.0);
    const SpringTrial t = EvaluateSpring(b.springs[i], s->committed[i], u);
    s->trial[i] = t.state;
    s->story_force_kN[i] = t.force_kN;
    s->story_tangent_kN_per_mm[i] = t.tangent_kN_per_mm;
  }
  for (int i = 0; i < n; ++i)
    s->restoring_kN(i) = s->story_force_kN[i] - (i + 1 < n ? s->story_force_kN[i + 1] : 0.0);
}

void AssembleTangent(const NonlinearBuilding& b, const BuildingState& s, Eigen::MatrixXd* Kt) {
  const int n = b.dofs();
  Kt->setZero();
  for (int i = 0; i < n; ++i) {
    const double k = s.story_tangent_kN_per_mm[i];
    (*Kt)(i, i) += k;
    if (i > 0) {
      (*Kt)(i - 1, i - 1) += k;
      (*Kt)(i - 1, i) -= k;
      (*Kt)(i, i - 1) -= k;
    }
  }
}

void Commit(BuildingState* s) {
  std::copy(s->trial.begin(), s->trial.end(), s->committed.begin());
}

}  // namespace rths::models
