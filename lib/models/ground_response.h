#pragma once
/// @file The response of a structure without a specimen to a ground acceleration, integrated
/// offline: the RTHS benchmark's monolithic reference structure (docs/benchmark.md, criteria J4-J9).
#include <span>
#include <vector>

#include "models/structure.h"

namespace rths::models {

/// The response x_k [mm] of `structure` (no specimen force) at dt_s [s] to the ground acceleration
/// a_g,k [mm/s^2], from rest, by the integrator's central difference (Eqs. 1-3): x_0 = 0 and
/// x_k+1 from x_k, x_k-1 and a_g,k, so x_k depends on a_g up to k-1 exactly as the integrator's
/// x_k does. One row per DOF, one column per sample k = 0..N-1 (N = the ground's length):
/// x[i][k] for floor i + 1. Throws rths::Error if dt_s is at or above the central-difference
/// stability limit of `structure` (CentralDifference::Make).
std::vector<std::vector<double>> GroundResponse(const LinearStructure& structure, double dt_s,
                                                std::span<const double> ground_acc_mm_s2);

}  // namespace rths::models
