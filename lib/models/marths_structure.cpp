#include "models/marths_structure.h"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models::marths {

namespace {

void CheckFrameMatrix(const Eigen::MatrixXd& A, const char* name, Eigen::Index n) {
  if (A.rows() != n || A.cols() != n) {
    throw Error(fmt::format("maRTHS structure: {}", name),
                fmt::format("{} x {} matrix, expected {} x {} (square, K and M alike)", A.rows(), A.cols(), n, n));
  }
  if (!A.allFinite()) throw Error(fmt::format("maRTHS structure: {}", name), "a value is not finite");
  const double scale = A.cwiseAbs().maxCoeff();
  if ((A - A.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    throw Error(fmt::format("maRTHS structure: {}", name), "not symmetric (relative 1e-9)");
  }
}

/// The first value that `a` holds twice, or 0 (DOFs are >= 1).
template <std::size_t N>
int Repeated(const std::array<int, N>& a) {
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = i + 1; j < N; ++j) {
      if (a[i] == a[j]) return a[i];
    }
  }
  return 0;
}

}  // namespace

std::string FrameDofsProblem(const FrameDofs& d, int n_dofs) {
  const std::array<int, 7> named = {d.x(), d.theta(), d.theta2(), d.x2(), d.theta_2nd(), d.x3(), d.theta_3rd()};
  for (int dof : named) {
    if (dof < 1 || dof > n_dofs) return fmt::format("DOF {} is outside the model's 1..{}", dof, n_dofs);
  }
  for (int dof : d.ground) {
    if (dof < 1 || dof > n_dofs) return fmt::format("ground DOF {} is outside the model's 1..{}", dof, n_dofs);
  }
  if (const int twice = Repeated(named)) {
    return fmt::format("DOF {} is named twice among the interface and story DOFs", twice);
  }
  if (const int twice = Repeated(d.ground)) return fmt::format("ground DOF {} is named twice", twice);
  return "";
}

Eigen::MatrixXd RayleighDamping(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double w_i,
                                double w_j, double zeta) {
  Eigen::Matrix2d A;
  A << 0.5 / w_i, 0.5 * w_i, 0.5 / w_j, 0.5 * w_j;
  const Eigen::Vector2d a = A.inverse() * Eigen::Vector2d(zeta, zeta);
  return a(0) * M + a(1) * K;
}

IdealPhysical BuildIdealPhysical(double density_kg_m3) {
  constexpr double kInch = 25.4 / 1000.0;  // [m]
  const double Lb = 762.0 / 1000.0, Lc = 635.0 / 1000.0;
  const double Ic = 2.520 * std::pow(kInch, 4), Ib = 0.6132 * std::pow(kInch, 4);
  const double Ac = 1.670 * kInch * kInch, Ab = 0.947 * kInch * kInch;
  const double E = 200e9;
  IdealPhysical p;
  const double mass_b = density_kg_m3 * Ab * Lb, mass_c = density_kg_m3 * Ac * Lc;
  const double J = (mass_b / 2.0) * (Lb * Lb) / 12.0 + (mass_c / 2.0) * (Lc * Lc) / 12.0;
  p.M = Eigen::Vector3d(mass_b + mass_c, J, J).asDiagonal();
  const double kc3 = 3.0 * E * Ic / (Lc * Lc), rot = 3.0 * E * Ic / Lc + 4.0 * E * Ib / Lb;
  p.K << 2.0 * (3.0 * Ic * E / (Lc * Lc * Lc)), -kc3, -kc3,  //
      -kc3, rot, -2.0 * E * Ib / Lb,                          //
      -kc3, -2.0 * E * Ib / Lb, rot;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> eig(p.K, p.M,
                                                                      Eigen::EigenvaluesOnly);
  const double w1 = std::sqrt(eig.eigenvalues()(0)), w2 = std::sqrt(eig.eigenvalues()(2));
  p.C = RayleighDamping(p.M, p.K, w1, w2, 0.05);
  return p;
}

Structures BuildStructures(const Eigen::MatrixXd& K_ref, const Eigen::MatrixXd& M_ref,
                           double ideal_density_kg_m3, const FrameDofs& dofs) {
  const Eigen::Index n = M_ref.rows();  // K is checked against M's size, then M against itself
  CheckFrameMatrix(K_ref, "K (reference_K_N_per_m.csv)", n);
  CheckFrameMatrix(M_ref, "M (reference_M_kg.csv)", n);
  if (const std::string why = FrameDofsProblem(dofs, static_cast<int>(n)); !why.empty()) {
    throw Error("maRTHS structure: DOFs", why);
  }
  Structures s;
  s.dofs = dofs;
  s.reference.K = K_ref;
  s.reference.M = M_ref;
  s.reference.C = RayleighDamping(M_ref, K_ref, 13.493, 165.125, 0.05);
  s.reference.l = Eigen::VectorXd::Zero(n);
  for (int dof : dofs.ground) s.reference.l(Index(dof)) = 1.0;
  s.physical = BuildIdealPhysical(ideal_density_kg_m3);
  s.numerical = s.reference;
  const std::array<int, 3> physical = dofs.physical();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const int a = Index(physical[i]), b = Index(physical[j]);
      s.numerical.K(a, b) -= s.physical.K(i, j);
      s.numerical.C(a, b) -= s.physical.C(i, j);
    }
  }
  s.numerical.M(Index(dofs.x()), Index(dofs.x())) -= s.physical.M(0, 0);
  return s;
}

}  // namespace rths::models::marths
