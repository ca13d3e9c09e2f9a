#pragma once
/// @file Linear n-DOF numerical substructure and the central-difference integrator (Eqs. 1-3).
/// Units: mm, kN, s; mass in kN s^2/mm (= kg * 1e-6), stiffness kN/mm, damping kN s/mm.
///
/// Equation of motion at step k (Eq. 1), relative displacements x, ground acceleration a_g:
///
///     M x''_k + C x'_k + K x_k + s f_k = -M iota a_g,k
///
/// s = specimen_dir, f_k the measured specimen force [kN]: a positive f resists a positive
/// displacement of the actuator DOF (the damper force of Eq. 34 enters with this sign).
/// Central differences (Eqs. 2, 3): x'_k = (x_{k+1} - x_{k-1}) / (2 dt),
/// x''_k = (x_{k+1} - 2 x_k + x_{k-1}) / dt^2, which make x_{k+1} explicit:
///
///     (M/dt^2 + C/(2dt)) x_{k+1} = (2M/dt^2 - K) x_k - (M/dt^2 - C/(2dt)) x_{k-1}
///                                  - M iota a_g,k - s f_k.
///
/// Stable for dt < T_min / pi = 2 / w_max (w_max the highest natural circular frequency).
#include <Eigen/Core>

namespace rths::models {

/// Immutable structural model.
struct LinearStructure {
  Eigen::MatrixXd M;             ///< mass [kN s^2/mm], n x n, symmetric positive definite
  Eigen::MatrixXd C;             ///< damping [kN s/mm], n x n
  Eigen::MatrixXd K;             ///< stiffness [kN/mm], n x n, symmetric positive semidefinite
  /// Ground influence vector [-]: the ground load is -M iota a_g, the absolute accelerations
  /// x'' + iota a_g (ones for a shear building; Make sets ones, StructureFromScenario a structure
  /// file's iota line: models/structure_file.h).
  Eigen::VectorXd iota;
  Eigen::VectorXd specimen_dir;  ///< force location: unit vector at actuator_dof x specimen count
  int actuator_dof = 0;          ///< DOF the actuator (specimen) is attached to

  /// SDOF: m = mass_kg * 1e-6 [kN s^2/mm], K = m w^2, C = 2 zeta m w, w = 2 pi frequency_hz,
  /// specimen_dir = [specimen_count]. Throws rths::Error for mass, frequency <= 0, damping
  /// outside [0, 1) or specimen_count < 0 (0: no specimen force acts, a structure alone).
  static LinearStructure Sdof(double mass_kg, double frequency_hz, double damping_ratio,
                              double specimen_count);
  /// General n-DOF model from matrices in project units, iota = ones. Throws rths::Error for
  /// mismatched sizes, an M that is not symmetric positive definite, an actuator_dof out of
  /// range or specimen_count < 0.
  static LinearStructure Make(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                              const Eigen::MatrixXd& K, int actuator_dof, double specimen_count);
  int dofs() const { return static_cast<int>(M.rows()); }
};

/// Immutable central-difference integrator for one structure and step.
struct CentralDifference {
  double dt_s = 0.0;              ///< step [s]
  double max_frequency_hz = 0.0;  ///< highest natural frequency of (M, K) [Hz]
  double dt_limit_s = 0.0;        ///< stability limit T_min / pi [s]
  Eigen::MatrixXd P_x;            ///< Khat^-1 (2M/dt^2 - K), multiplies x_k
  Eigen::MatrixXd P_xprev;        ///< -Khat^-1 (M/dt^2 - C/(2dt)), multiplies x_{k-1}
  Eigen::VectorXd p_ground;       ///< -Khat^-1 M iota [s^2], multiplies a_g,k [mm/s^2]
  Eigen::VectorXd p_force;        ///< -Khat^-1 s [mm/kN], multiplies f_k [kN]
  Eigen::VectorXd iota;           ///< ground influence (for absolute accelerations)
  Eigen::MatrixXd M, C, K;        ///< the structure's matrices (initial conditions)

  /// Precomputes the recurrence, with Khat = M/dt^2 + C/(2dt). Throws rths::Error for dt <= 0
  /// and, if enforce_stability_limit, for dt >= T_min / pi, naming the highest natural
  /// frequency and the limit (pass false only to study the unstable recurrence).
  static CentralDifference Make(const LinearStructure& s, double dt_s,
                                bool enforce_stability_limit = true);
  int dofs() const { return static_cast<int>(P_x.rows()); }
};

/// Per-step state, preallocated by MakeState(). Before Advance() of step k it holds x_k and
/// x_{k-1}; after it, x_{k+1} and x_k, and the velocity/acceleration at k.
struct StructureState {
  long k = 0;                    ///< index of x: x = x_k
  Eigen::VectorXd x_prev;        ///< x_{k-1} [mm]
  Eigen::VectorXd x;             ///< x_k [mm]
  Eigen::VectorXd vel_prev;      ///< x'_{k-1} by Eq. 2 [mm/s] (valid after the first Advance)
  Eigen::VectorXd acc_prev;      ///< x''_{k-1} by Eq. 3, relative [mm/s^2]
  Eigen::VectorXd abs_acc_prev;  ///< x''_{k-1} + iota a_g,k-1, absolute [mm/s^2]
  Eigen::VectorXd x_next;        ///< workspace
};

/// A structure at rest at k = 0 (x_0 = x_{-1} = 0), every vector sized once.
StructureState MakeState(const CentralDifference& cd);
/// Initial conditions x_0 [mm], x'_0 [mm/s] at k = 0 with the second-order start
/// x_{-1} = x_0 - dt x'_0 + dt^2/2 x''_0, x''_0 = M^-1 (-M iota a_g0 - s f0 - C x'_0 - K x_0)
/// (here with a_g0 = f0 = 0).
void SetInitialConditions(const CentralDifference& cd, StructureState* s, const Eigen::VectorXd& x0,
                          const Eigen::VectorXd& v0);

/// Step k: from x_k, x_{k-1}, the ground acceleration a_g,k [mm/s^2] and the specimen force f_k
/// [kN] measured at k, computes x_{k+1}; then exposes x = x_{k+1}, x_prev = x_k, and the
/// velocity, relative and absolute acceleration at k. Allocates nothing.
void Advance(const CentralDifference& cd, StructureState* s, double ground_acc_mm_s2,
             double specimen_force_kN);

}  // namespace rths::models
