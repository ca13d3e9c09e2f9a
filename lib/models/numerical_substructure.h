#pragma once
/// @file The numerical substructure the clock integrates, one step at a time (docs/lockstep.md,
/// desired_t): in "rths" mode the linear structure under the ground acceleration and the force
/// measured on the experimental substructure, by central difference (Eqs. 1-3) or by the RTHS
/// benchmark's reference-code loop (RK4 with the force one sample late, structure.integrator =
/// "rk4_unit_delay"); in "predefined" mode a prescribed displacement history. The model is
/// immutable; its state is one struct.
#include <cstdint>
#include <optional>
#include <vector>

#include "models/continuous_structure.h"
#include "models/structure.h"
#include "models/structure_integrator.h"

namespace rths::models {

struct NumericalSubstructure {
  /// "predefined": r_k = r_mm[k] [mm], one degree of freedom; nothing is integrated.
  static NumericalSubstructure Predefined(std::vector<double> r_mm);
  /// "rths": `structure` integrated with step `dt_s` [s] under a_g,k = ground_mm_s2[k] [mm/s^2],
  /// by central difference (Eqs. 1-3).
  static NumericalSubstructure Integrated(const LinearStructure& structure, double dt_s,
                                          std::vector<double> ground_mm_s2);
  /// "rths" with structure.integrator = "rk4_unit_delay": x_k from x_{k-1} by one RK4 step
  /// (models/continuous_structure.h) with a_g at t_{k-1}, t_{k-1} + dt/2, t_k from
  /// ground_half_mm_s2 (a_g(j dt/2), 2N + 1 values for N steps) and the force measured at k-2 held
  /// over the step: the reference code's Unit Delay on the measured force, which then acts over
  /// [t_{k-1}, t_k]. ground_mm_s2 is a_g,k as Integrated takes it (logged in desired_t).
  static NumericalSubstructure Rk4UnitDelay(const LinearStructure& structure, double dt_s,
                                            std::vector<double> ground_mm_s2, std::vector<double> ground_half_mm_s2);

  /// "rths" with a hysteretic structure or another integrator (cr, alpha_os, newmark_implicit;
  /// models/structure_integrator.h): x_k = Advance(x_{k-1}, a_g,k-1, a_g,k, f_{k-1}), the measured
  /// force entering as each method prescribes (its header).
  static NumericalSubstructure Stepped(const StructureIntegrator& integrator, std::vector<double> ground_mm_s2);

  bool predefined() const { return !cd.has_value() && !stepped.has_value(); }

  std::optional<CentralDifference> cd;  ///< "rths" mode (also for rk4: its stability limit and sizes)
  std::optional<ContinuousStructure> rk4;  ///< "rths" with rk4_unit_delay
  std::optional<StructureIntegrator> stepped;  ///< "rths" by Stepped
  double dt_s = 0.0;                    ///< step [s]
  int dof = 0;                          ///< the actuator's degree of freedom ("rths" mode)
  std::vector<double> r_mm;             ///< r_k for every step ("predefined" mode) [mm]
  std::vector<double> ground_mm_s2;     ///< a_g,k for every step ("rths" mode) [mm/s^2]
  std::vector<double> ground_half_mm_s2;  ///< a_g(j dt/2), rk4 only [mm/s^2]
};

/// Per-step state: `structure` holds x = x_k and, after the first step, abs_acc_prev (the
/// absolute accelerations at k-1; for Stepped, the method's newest acceleration plus iota a_g,k-1)
/// whichever the integrator; the rest is the integrator's own.
struct SubstructureState {
  StructureState structure;
  Eigen::VectorXd z;         ///< rk4: [x_k; x'_k] [mm, mm/s]
  Rk4Workspace rk;           ///< rk4: the stages
  double f_delayed_kN = 0.0; ///< rk4: the force measured at k-1, used in the next step [kN]
  IntegratorState stepped;   ///< Stepped: the method's state, springs included
};

/// At rest at k = 0, every vector sized once (x has one entry in "predefined" mode).
SubstructureState MakeState(const NumericalSubstructure& m);

/// Step k: x_k from the state at k-1, a_g and the force f_{k-1} [kN] measured at sample k-1
/// (central difference: Eq. 1 with Eqs. 2-3, f_{k-1} acting at t_{k-1}; rk4_unit_delay: f_{k-2}
/// held over [t_{k-1}, t_k]; nothing to integrate at k = 0), or x_k = r_k ("predefined"). Returns
/// r_k = x_k at the actuator [mm]. No allocation.
double Step(const NumericalSubstructure& m, SubstructureState* s, std::int64_t k, double f_prev_kN);

/// a_g,k [mm/s^2] (0 in "predefined" mode).
inline double GroundAt(const NumericalSubstructure& m, std::int64_t k) {
  return m.predefined() ? 0.0 : m.ground_mm_s2[static_cast<std::size_t>(k)];
}

}  // namespace rths::models
