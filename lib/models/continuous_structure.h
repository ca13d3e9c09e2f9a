#pragma once
/// @file A linear structure as a continuous first-order system, stepped by classical RK4 with the
/// specimen force held over the step: the RTHS benchmark's reference code integrates its numerical
/// substructure this way (a fixed-step ode4 in Simulink, Silva et al. 2020; docs/benchmark.md "How
/// the loop is closed"), and its monolithic reference structure continuously (lsim).
///
/// State z = [x; x'] [mm, mm/s], n = dofs:
///
///     z' = A z + b_g a_g(t) + b_f f,   A = [[0, I], [-M^-1 K, -M^-1 C]],
///     b_g = [0; -iota],  b_f = [0; -M^-1 s]
///
/// (Eq. 1 of the paper as a first-order system; s = specimen_dir, f [kN] the measured force). One
/// step of RK4 over dt takes a_g at t, t + dt/2 and t + dt (the record's linear interpolation, as
/// Simulink's From File gives it) and f held:
///
///     k1 = F(z, a_g(t)),  k2 = F(z + dt/2 k1, a_g(t + dt/2)),  k3 = F(z + dt/2 k2, a_g(t + dt/2)),
///     k4 = F(z + dt k3, a_g(t + dt)),   z <- z + dt/6 (k1 + 2 k2 + 2 k3 + k4).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "models/structure.h"

namespace rths::models {

/// Immutable: the system matrices of a structure.
struct ContinuousStructure {
  Eigen::MatrixXd A;        ///< 2n x 2n [1/s, 1/s^2]
  Eigen::VectorXd b_g;      ///< 2n: multiplies a_g [mm/s^2]
  Eigen::VectorXd b_f;      ///< 2n: multiplies f [kN] (zero without a specimen)
  int n = 0;                ///< degrees of freedom

  /// From M, C, K, iota and specimen_dir of `s` (M must be invertible: LinearStructure::Make checks it).
  static ContinuousStructure Make(const LinearStructure& s);
};

/// The state and the RK4 stages, sized once (Rk4Workspace::Make): a step allocates nothing.
struct Rk4Workspace {
  Eigen::VectorXd k1, k2, k3, k4, z_stage;
  static Rk4Workspace Make(const ContinuousStructure& c);
};

/// One RK4 step of `c` over dt_s [s] from z (in place), a_g [mm/s^2] at t, t + dt/2, t + dt
/// (ag[0..2]) and the force f_kN held. Allocates nothing.
void Rk4Step(const ContinuousStructure& c, Rk4Workspace* w, Eigen::VectorXd* z, double dt_s, const double ag[3],
             double f_kN);

/// The response x_k [mm] of `structure` without a specimen force from rest, by Rk4Step at dt_s,
/// with a_g at the half steps: ground_half_mm_s2[j] = a_g(j dt/2), 2N + 1 values for N samples.
/// One row per DOF, x[i][k] for floor i + 1, k = 0..N-1 (x_0 = 0), as GroundResponse lays it out.
std::vector<std::vector<double>> GroundResponseRk4(const LinearStructure& structure, double dt_s,
                                                   std::span<const double> ground_half_mm_s2);

}  // namespace rths::models
