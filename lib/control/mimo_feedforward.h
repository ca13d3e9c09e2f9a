#pragma once
/// @file A MIMO model-inverse feedforward for the maRTHS benchmark's two coupled actuators: the
/// paper's feedforward (Phillips & Spencer 2013, Eqs. 16-19: the inverse of the identified plant,
/// driven by the target and its derivatives from Eqs. 20-22) extended from one actuator to the
/// 2 x 2 identified plant H(s) of lib/models/marths_plant.h (docs/marths.md "Our compensators").
///
/// Both rows of a column of H share that column's denominator d_j(s), so H = N D^-1 with
/// D = diag(d_1, d_2) and N the numerators, and
///
///     H^-1 = D N^-1 = D adj(N) / det N,
///     det N = (s - z_1)(s - z_2) [k11 k22 (s - z_22) - k21 k12 (s - z_12)],
///
/// whose roots, the transmission zeros of H, are in the left half plane for the identified plant
/// (z_1, z_2 and -31.9 rad/s): the inverse is stable. It is improper (up to s^3 more zeros than
/// poles in an element), as the paper's single-actuator inverse is. Each element is split by
/// polynomial division, num = Q den + R (deg R < deg den, the common factor (s - z_1)(s - z_2)
/// cancelled in the second row), into
///
///     u_i = sum_j [ Q_ij(s) x_j + (R_ij / den_ij)(s) x_j ]:
///
/// the polynomial part applied to the target and its derivatives x_j, x_j', x_j'', x_j''' by
/// Eqs. 20-22 (what makes the inverse proper, exactly as the paper's feedforward does), the
/// strictly proper rest a stable filter discretised by Tustin at the loop's step.
#include <array>

#include <Eigen/Core>

#include "control/feedforward.h"
#include "control/transfer_function.h"
#include "models/marths_plant.h"

namespace rths::control {

/// The design (immutable).
struct MimoFeedforward {
  /// q[i][j][m]: coefficient of s^m of Q_ij (m = 0 .. 3).
  std::array<std::array<std::array<double, 4>, 2>, 2> q{};
  /// The strictly proper rests R_ij / den_ij, discretised.
  std::array<std::array<DiscreteTf, 2>, 2> rest;
  double dt_s = 0.0;
};

/// Designs the inverse of `p` at step dt_s. Throws rths::Error if a transmission zero is not in
/// the left half plane (the inverse would be unstable) or dt_s is not > 0.
MimoFeedforward MakeMimoFeedforward(const models::marths::PlantZpk& p, double dt_s);

/// Per-step state: each target's extrapolation (Eqs. 20-22) and the four filters.
struct MimoFeedforwardState {
  std::array<ExtrapolationState, 2> targets{};
  std::array<std::array<TfFilterState, 2>, 2> rest{};
};

/// [u_1, u_2] [mm] for the targets x_t,1 and x_t,2 [mm] of this step. Allocates nothing.
Eigen::Vector2d MimoFeedforwardStep(const MimoFeedforward& f, MimoFeedforwardState* s, double target1_mm,
                                    double target2_mm);

}  // namespace rths::control
