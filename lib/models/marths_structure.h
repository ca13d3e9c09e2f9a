#pragma once
/// @file The structures of the multi-axial RTHS benchmark (maRTHS; Condori Uribe et al., Front.
/// Built Environ. 2023; reference code FermandoisLab/maRTHS-bmk-RoDeAC, docs/marths.md): the
/// 29-DOF reference frame, the ideal physical substructure, and the numerical substructure = the
/// reference minus it, as the reference code builds them.
///
/// **Units: SI (m, rad, N, N m, kg, kg m^2, s), as the reference code's matrices are.** A DOF is a
/// translation [m] or a rotation [rad]; its force is N or N m. The loop converts at its edges
/// (actuator displacements in mm).
///
/// DOFs are numbered 1..29 as in the reference code (Support_files/FE_Model/REF_SAP2000_Model/
/// Joint_DOF.xlsx): the interface node's translation 27 and rotation 21, the rotation 29 of the
/// frame's other top node (not driven), the second story's translation 26 and rotation 22, the
/// third story's translation 13 and rotation 3. The ground acceleration loads the three floor
/// translations 13, 26, 27 (the Ux column of Joint_DOF.xlsx; every other DOF has influence 0).
///
/// Reference (build_reference.m): K_r, M_r from the SAP2000 export (data/marths/reference_*.csv),
/// Rayleigh damping C_r = a_M M_r + a_K K_r with 5 % at w_i = 13.493 and w_j = 165.125 rad/s:
///
///     [a_M, a_K]^T = inv(0.5 [[1/w_i, w_i], [1/w_j, w_j]]) [zeta, zeta]^T.
///
/// Ideal physical substructure (build_physical_ideal.m): the first story's bay as a 3-DOF frame
/// (x_27, theta_29, theta_21), beam L_b = 0.762 m, columns L_c = 0.635 m, I_c = 2.520 in^4,
/// I_b = 0.6132 in^4, A_c = 1.670 in^2, A_b = 0.947 in^2, E = 200 GPa, and the density the code
/// uses, 785e3 kg/m^3 (100 x steel's; kept as coded: docs/marths.md "Decisions"):
///
///     K_p = [[6 E I_c / L_c^3, -3 E I_c / L_c^2, -3 E I_c / L_c^2],
///            [-3 E I_c / L_c^2, 3 E I_c / L_c + 4 E I_b / L_b, -2 E I_b / L_b],
///            [-3 E I_c / L_c^2, -2 E I_b / L_b, 3 E I_c / L_c + 4 E I_b / L_b]]
///     M_p = diag(m_b + m_c, J, J),  J = (m_b / 2) L_b^2 / 12 + (m_c / 2) L_c^2 / 12
///     C_p = Rayleigh, 5 % at the first and third frequency of (K_p, M_p)
///
/// Numerical (build_numerical.m): K_n = K_r - K_p and C_n = C_r - C_p on the DOFs (27, 29, 21);
/// M_n = M_r - M_p(1,1) at DOF 27 only (the code zeroes the rotational masses before subtracting).
#include <array>
#include <string>

#include <Eigen/Core>

namespace rths::models::marths {

/// Number of DOFs of the maRTHS frame models.
inline constexpr int kDofs = 29;
/// The reference code's DOF numbers (1-based).
inline constexpr int kDofX = 27;        ///< interface node, translation (floor 1) [m]
inline constexpr int kDofTheta = 21;    ///< interface node, rotation (driven) [rad]
inline constexpr int kDofTheta2 = 29;   ///< the frame's other top node, rotation (not driven) [rad]
inline constexpr int kDofX2 = 26;       ///< second story, translation [m]
inline constexpr int kDofTheta2nd = 22; ///< second story, rotation [rad]
inline constexpr int kDofX3 = 13;       ///< third story, translation [m]
inline constexpr int kDofTheta3rd = 3;  ///< third story, rotation [rad]
/// The DOFs the ground acceleration loads (influence 1).
inline constexpr std::array<int, 3> kGroundDofs = {13, 26, 27};

/// Where the benchmark's quantities sit among a frame model's DOFs (1-based, as Joint_DOF.xlsx
/// numbers them): the reference code's numbering by default. A lab's own model of the frame
/// (another mesh or numbering; [marths] interface_dofs, story_dofs, ground_dofs) declares its own;
/// the physical bay is subtracted at (x, theta2, theta) in K_p's order.
struct FrameDofs {
  /// The interface node's translation x, its driven rotation theta, the other top node's
  /// rotation theta2 (not driven): where the feedback frame's F, M_theta, M_theta2 enter.
  std::array<int, 3> interface = {kDofX, kDofTheta, kDofTheta2};
  /// Second story translation and rotation, third story translation and rotation (J8-J10).
  std::array<int, 4> stories = {kDofX2, kDofTheta2nd, kDofX3, kDofTheta3rd};
  /// The DOFs the ground acceleration loads (influence 1).
  std::array<int, 3> ground = kGroundDofs;
  int x() const { return interface[0]; }
  int theta() const { return interface[1]; }
  int theta2() const { return interface[2]; }
  int x2() const { return stories[0]; }
  int theta_2nd() const { return stories[1]; }
  int x3() const { return stories[2]; }
  int theta_3rd() const { return stories[3]; }
  /// The physical substructure's DOFs in K_p's order (x, theta2, theta).
  std::array<int, 3> physical() const { return {x(), theta2(), theta()}; }
  bool operator==(const FrameDofs&) const = default;
};

/// What is wrong with `d` for a model of `n_dofs` DOFs, or "": a DOF outside [1, n_dofs], the
/// interface and story DOFs not seven distinct ones, the ground DOFs not distinct.
std::string FrameDofsProblem(const FrameDofs& d, int n_dofs);

/// Mass, damping and stiffness of a frame model, SI.
struct FrameMatrices {
  Eigen::MatrixXd M;  ///< [kg, kg m^2]
  Eigen::MatrixXd C;  ///< [N s/m, N m s/rad]
  Eigen::MatrixXd K;  ///< [N/m, N m/rad]
  Eigen::VectorXd l;  ///< ground influence [-]: 1 at the ground DOFs (FrameDofs::ground)
};

/// The ideal physical substructure (3 x 3, DOFs FrameDofs::physical()).
struct IdealPhysical {
  Eigen::Matrix3d M, C, K;
};

/// Rayleigh damping a_M M + a_K K with ratio `zeta` at w_i and w_j [rad/s] (build_reference.m).
Eigen::MatrixXd RayleighDamping(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double w_i,
                                double w_j, double zeta);

/// build_physical_ideal.m at density `density_kg_m3` (the reference code: 785e3).
IdealPhysical BuildIdealPhysical(double density_kg_m3 = 785e3);

/// The reference structure and the numerical substructure.
struct Structures {
  FrameMatrices reference;
  FrameMatrices numerical;
  IdealPhysical physical;
  FrameDofs dofs;  ///< where the interface, the stories and the ground load are
};

/// From the reference matrices (the SAP2000 export: 29 x 29, SI; a lab's own model: n x n with
/// its `dofs`): the reference with its Rayleigh damping and the numerical substructure (the file
/// comment). Throws rths::Error if a matrix is not square, K and M differ in size, one is not
/// symmetric (relative 1e-9) or holds a value that is not finite, or FrameDofsProblem refuses `dofs`.
Structures BuildStructures(const Eigen::MatrixXd& K_ref, const Eigen::MatrixXd& M_ref,
                           double ideal_density_kg_m3 = 785e3, const FrameDofs& dofs = {});

/// The 0-based index of a 1-based DOF number.
constexpr int Index(int dof) { return dof - 1; }

}  // namespace rths::models::marths
