#pragma once
/// @file The shear building a full stiffness matrix is closest to in its first mode: story
/// stiffnesses [kN/mm] from the story shears and drifts under the first mode's inertia forces.
/// Used to give a structure whose K is not tridiagonal (the RTHS benchmark's 3-story frame,
/// benchmark_structures.h) story springs that can yield (docs/structures.md, "The benchmark
/// structure, yielding").
#include <vector>

#include <Eigen/Core>

namespace rths::models {

/// Story stiffnesses k_i = V_i / d_i [kN/mm] of the equivalent shear building of (M, K): load the
/// structure by the first mode's inertia forces F = M phi_1 (K phi_1 = w_1^2 M phi_1, the lowest
/// mode), solve x = K^-1 F = phi_1 / w_1^2, and take story i's shear V_i = sum_{j >= i} F_j and its
/// drift d_i = x_i - x_{i-1} (x_0 = 0). The shear building of these stiffnesses carries F with the
/// same x, so it has the same first frequency and first mode shape exactly; higher modes differ
/// (the story-stiffness definition of a lateral-load analysis, here with the modal load pattern).
/// M diagonal [kN s^2/mm or kg: only the shape matters], K symmetric positive definite [kN/mm],
/// floor 1 first. Throws rths::Error("K", ...) if the sizes differ, K is not positive definite, or
/// a story's drift or shear under the pattern is not positive (a first mode that reverses, which
/// no shear building with positive stiffnesses has).
std::vector<double> FirstModeStoryStiffness(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K);

}  // namespace rths::models
