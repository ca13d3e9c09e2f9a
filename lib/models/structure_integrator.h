#pragma once
/// @file The integrator RTHS runs a NonlinearBuilding with (docs/structures.md, "Integrators"):
/// one of central_difference, cr, alpha_os, newmark_implicit, chosen by IntegratorConfig, behind
/// one call per RTHS step. Each method's equations, citation, and where the measured force enters
/// are in its header (integrator_cd.h, integrator_cr.h, integrator_alpha_os.h,
/// integrator_newmark.h).
///
/// Use (the lockstep's step k, f_k measured at the command of sample k):
///
///     const StructureIntegrator integ = StructureIntegrator::Make(building, dt_s, config);
///     IntegratorState s = MakeIntegratorState(building);       // at rest; s.x = command of k = 0
///     for k: impose s.x[dof]; measure f_k;
///            Advance(integ, &s, a_g[k], a_g[k + 1], f_k);       // s.x = command of k + 1
///
/// Advance allocates nothing.
#include <array>
#include <variant>
#include <vector>

#include "models/integrator_alpha_os.h"
#include "models/integrator_cd.h"
#include "models/integrator_config.h"
#include "models/integrator_cr.h"
#include "models/integrator_newmark.h"
#include "models/integrator_state.h"
#include "models/nonlinear_building.h"

namespace rths::models {

struct StructureIntegrator {
  NonlinearBuilding building;
  IntegratorConfig config;
  double dt_s = 0.0;  ///< RTHS step [s]
  std::variant<NonlinearCentralDifference, ChenRicles, AlphaOs, NewmarkImplicit> method;

  /// Validates config and precomputes the method. Throws rths::Error (central_difference: also at
  /// or above its stability limit; rk4_unit_delay: not for a NonlinearBuilding, see
  /// numerical_substructure.h).
  static StructureIntegrator Make(const NonlinearBuilding& b, double dt_s, const IntegratorConfig& config);
};

/// One RTHS step k -> k + 1 (see @file): a_g,k, a_g,k+1 [mm/s^2], f_k [kN] measured at s->x.
void Advance(const StructureIntegrator& m, IntegratorState* s, double ground_mm_s2,
             double ground_next_mm_s2, double force_kN);

/// What a run of an integrator over a record gives.
struct SimulatedRun {
  Eigen::MatrixXd x_mm;                ///< n x N: column k = the command of sample k [mm]
  double hysteretic_energy_kN_mm = 0;  ///< sum over the springs at the end [kN mm]
  double max_residual_kN = 0;          ///< newmark_implicit: largest residual left [kN]; 0 otherwise
};

/// Runs m from rest over N = ground_mm_s2.size() samples (a_g at sample k [mm/s^2]; a_g,N taken
/// as a_g,N-1), with f_k = force_kN[k] [kN] (empty: no specimen force). Throws rths::Error for a
/// force history of another length. For tests, studies and benches: allocates the history.
SimulatedRun Simulate(const StructureIntegrator& m, const std::vector<double>& ground_mm_s2,
                      const std::vector<double>& force_kN = {});

}  // namespace rths::models
