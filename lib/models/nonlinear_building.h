#pragma once
/// @file A shear building whose stories are hysteretic springs (models/story_spring.h): the
/// numerical substructure of docs/structures.md, "Nonlinear stories". Units: mm, kN, s; mass
/// kN s^2/mm (= kg * 1e-6).
///
/// Equation of motion (Eq. 1 with a nonlinear restoring force):
///
///     M x'' + C x' + R(x) + s f = -M iota a_g
///
/// x the floor displacements relative to the ground (floor 1 first), R_i = F_i(u_i) - F_{i+1}(u_{i+1})
/// with u_i = x_i - x_{i-1} the drift of story i (x_0 = 0: story 1 is between the ground and
/// floor 1), F_i the force of spring i, and s = specimen_dir (structure.h). C is constant,
/// built from the initial stiffness K0 = dR/dx at rest (RayleighDampingMatrix, or
/// ModalDampingMatrix of structure_file.h). The tangent K_t = dR/dx is tridiagonal.
#include <vector>

#include <Eigen/Core>

#include "models/story_spring.h"
#include "models/structure.h"

namespace rths::models {

/// Immutable model.
struct NonlinearBuilding {
  Eigen::MatrixXd M;              ///< mass [kN s^2/mm], diagonal
  Eigen::MatrixXd C;              ///< damping [kN s/mm]
  Eigen::MatrixXd K0;             ///< initial stiffness [kN/mm] (tangent at rest)
  Eigen::VectorXd iota;           ///< ground influence (ones)
  Eigen::VectorXd specimen_dir;   ///< unit vector at actuator_dof x specimen count
  int actuator_dof = 0;           ///< 0-based DOF the specimen acts on
  std::vector<SpringParams> springs;  ///< springs[i]: story i + 1
  bool all_linear = true;         ///< every spring linear (R = K0 x)

  /// floor_masses_kg[i] [kg] of floor i + 1, springs[i] of story i + 1 (validated), C [kN s/mm]
  /// (n x n; e.g. RayleighDampingMatrix(MassMatrix(masses), InitialStiffness(springs), ...)).
  /// Throws rths::Error("floor_masses_kg"|"springs[i]: field"|"C"|"actuator_dof"|
  /// "specimen_count", ...) naming the range.
  static NonlinearBuilding Make(const std::vector<double>& floor_masses_kg,
                                const std::vector<SpringParams>& springs, const Eigen::MatrixXd& C,
                                int actuator_dof, double specimen_count);
  int dofs() const { return static_cast<int>(M.rows()); }
  /// (M, C, K0) as a linear structure with this iota, specimen_dir, actuator_dof.
  LinearStructure Initial() const;
};

/// Diagonal mass matrix [kN s^2/mm] of floor masses [kg].
Eigen::MatrixXd MassMatrix(const std::vector<double>& floor_masses_kg);
/// Tridiagonal stiffness [kN/mm] of a shear building with story stiffnesses k_kN_per_mm (story 1
/// between the ground and floor 1).
Eigen::MatrixXd StoryStiffnessMatrix(const std::vector<double>& k_kN_per_mm);
/// StoryStiffnessMatrix of the springs' initial stiffnesses.
Eigen::MatrixXd InitialStiffness(const std::vector<SpringParams>& springs);
/// Rayleigh damping C = a0 M + a1 K [kN s/mm] with the ratios zeta_i, zeta_j in modes i, j of
/// (M, K) (1-based, i != j): zeta = a0 / (2 w) + a1 w / 2 at w_i and w_j. Throws rths::Error for a
/// mode out of range or equal frequencies, ratios outside [0, 1).
Eigen::MatrixXd RayleighDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, int mode_i,
                                      double zeta_i, int mode_j, double zeta_j);

/// The springs' committed states and a trial, preallocated (MakeBuildingState).
struct BuildingState {
  std::vector<SpringState> committed;  ///< per story, at the last Commit
  std::vector<SpringState> trial;      ///< per story, at the last Evaluate
  std::vector<double> story_force_kN;  ///< F_i at the trial [kN]
  std::vector<double> story_tangent_kN_per_mm;  ///< dF_i/du_i at the trial [kN/mm]
  Eigen::VectorXd restoring_kN;        ///< R at the trial [kN]
  /// Sum of the committed springs' hysteretic energies [kN mm].
  double HystereticEnergy() const;
};
BuildingState MakeBuildingState(const NonlinearBuilding& b);

/// Trial at floor displacements x [mm] from the committed states: fills trial, story forces and
/// tangents, and R(x) into s->restoring_kN. Committed states unchanged; no allocation.
void Evaluate(const NonlinearBuilding& b, const Eigen::VectorXd& x_mm, BuildingState* s);
/// K_t [kN/mm] at the last Evaluate into *Kt (n x n, preallocated; overwritten). No allocation.
void AssembleTangent(const NonlinearBuilding& b, const BuildingState& s, Eigen::MatrixXd* Kt);
/// Commits the last trial. No allocation.
void Commit(BuildingState* s);

}  // namespace rths::models
