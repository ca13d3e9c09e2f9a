#pragma once
/// @file The per-step state every structural integrator of a NonlinearBuilding advances
/// (models/structure_integrator.h): one struct, sized once by MakeIntegratorState, so that
/// Advance() allocates nothing. Which fields a method uses is said at each field.
#include <Eigen/Core>
#include <Eigen/LU>

#include "models/nonlinear_building.h"

namespace rths::models {

struct IntegratorState {
  long k = 0;                ///< RTHS steps taken: x is the command of sample k
  /// The displacement to impose at sample k [mm]: x_k (central_difference, cr, newmark_implicit),
  /// the predictor x~_k (alpha_os).
  Eigen::VectorXd x;
  Eigen::VectorXd x_prev;    ///< central_difference: x one (sub-)step before x; newmark: x_{k-1}
  Eigen::VectorXd v;         ///< velocity [mm/s]: at x (cr, newmark), at the last corrected step (alpha_os), at the last (sub-)step before x (central_difference)
  Eigen::VectorXd a;         ///< relative acceleration [mm/s^2], at the same time as v
  Eigen::VectorXd x_corr;    ///< alpha_os: the corrected x at the last solved step [mm]
  Eigen::VectorXd v_pred;    ///< alpha_os: predictor velocity v~ at x [mm/s]
  Eigen::VectorXd q_prev;    ///< alpha_os: M iota a_g + s f + C v + R~ + K0 (x - x~) at the last step [kN]
  bool started = false;      ///< alpha_os, newmark: the acceleration at rest has been solved
  double residual_kN = 0.0;  ///< newmark_implicit: |residual|_2 left by the last step's iterations [kN]
  BuildingState building;    ///< springs: committed at the last evaluated displacement
  // Workspaces.
  Eigen::VectorXd w1, w2, w3, w4;
  Eigen::MatrixXd J;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
};

/// At rest (every vector zero), sized for b.
IntegratorState MakeIntegratorState(const NonlinearBuilding& b);

}  // namespace rths::models
