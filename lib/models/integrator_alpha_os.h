#pragma once
/// @file The alpha operator-splitting method (Combescure & Pegon 1997, "alpha-Operator splitting
/// time integration technique for pseudodynamic testing. Error propagation analysis", Soil Dyn.
/// Earthquake Eng. 16:427-443), as OpenFresco runs it (OpenSees/OpenSees
/// SRC/analysis/integrator/AlphaOS.cpp, A. Schellenberg: the predictor and the corrector below,
/// with its alpha_OS = 1 + alpha), for a NonlinearBuilding (docs/structures.md, "Integrators").
///
/// alpha in [-1/3, 0], beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha. Predictor (explicit):
///
///     x~_{k+1} = x_k + dt v_k + dt^2 (1/2 - beta) a_k,    v~_{k+1} = v_k + dt (1 - gamma) a_k
///
/// x~_{k+1} is the command; f_{k+1} is measured there and R~_{k+1} = R(x~_{k+1}). Corrector:
/// the HHT-alpha equilibrium with the restoring force linearised by the initial stiffness,
/// R_{k+1} ~ R~_{k+1} + K0 (x_{k+1} - x~_{k+1}), x_{k+1} = x~_{k+1} + beta dt^2 a_{k+1},
/// v_{k+1} = v~_{k+1} + gamma dt a_{k+1}:
///
///     M a_{k+1} + (1 + alpha) Q_{k+1} - alpha Q_k = 0,
///     Q_k = M iota a_g,k + s f_k + C v_k + R~_k + K0 (x_k - x~_k),
///     [M + (1 + alpha)(gamma dt C + beta dt^2 K0)] a_{k+1}
///         = -(1 + alpha)(M iota a_g,k+1 + s f_{k+1} + C v~_{k+1} + R~_{k+1}) + alpha Q_k.
///
/// Where f enters: weighted, (1 + alpha) f_{k+1} - alpha f_k, both measured at predictors, as
/// Combescure & Pegon weight the restoring forces. OpenSees instead imposes the interpolated
/// predictor (1 + alpha) x~_{k+1} - alpha x~_k on its elements; for linear springs the two agree.
/// Unconditionally stable for linear and softening structures (with K0 >= K_t), second order,
/// numerical damping of the high modes growing with |alpha|. No sub-steps.
#include "models/integrator_state.h"
#include "models/nonlinear_building.h"

namespace rths::models {

struct AlphaOs {
  double alpha = 0.0, beta = 0.25, gamma = 0.5;
  double dt_s = 0.0;
  Eigen::MatrixXd m_inv;     ///< M^-1 (the start)
  Eigen::MatrixXd mhat_inv;  ///< [M + (1 + alpha)(gamma dt C + beta dt^2 K0)]^-1
  Eigen::VectorXd m_iota;    ///< M iota
  Eigen::MatrixXd K0;

  /// Throws rths::Error("alpha", ...) outside [-1/3, 0], or for dt_s <= 0.
  static AlphaOs Make(const NonlinearBuilding& b, double dt_s, double alpha);
};

/// Step k: s->x is the predictor x~_k, commanded, at which f_k [kN] was measured; a_g,k
/// [mm/s^2]. Solves the corrector at k (at k = 0 the equilibrium at rest), then leaves the next
/// predictor x~_{k+1} in s->x (and x_k, v_k, a_k in x_corr, v, a). Commits the springs at x~_k.
/// No allocation.
void Advance(const AlphaOs& m, const NonlinearBuilding& b, IntegratorState* s, double ground_mm_s2,
             double force_kN);

}  // namespace rths::models
