#pragma once
/// @file The numerical substructure the clock integrates, one step at a time (docs/lockstep.md,
/// desired_t): in "rths" mode the linear structure by central difference (Eqs. 1-3) under the
/// ground acceleration and the force measured on the experimental substructure; in "predefined"
/// mode a prescribed displacement history. The model is immutable; its state is one struct.
#include <cstdint>
#include <optional>
#include <vector>

#include "models/structure.h"

namespace rths::models {

struct NumericalSubstructure {
  /// "predefined": r_k = r_mm[k] [mm], one degree of freedom; nothing is integrated.
  static NumericalSubstructure Predefined(std::vector<double> r_mm);
  /// "rths": `structure` integrated with step `dt_s` [s] under a_g,k = ground_mm_s2[k] [mm/s^2].
  static NumericalSubstructure Integrated(const LinearStructure& structure, double dt_s,
                                          std::vector<double> ground_mm_s2);

  bool predefined() const { return !cd.has_value(); }

  std::optional<CentralDifference> cd;  ///< "rths" mode
  int dof = 0;                          ///< the actuator's degree of freedom ("rths" mode)
  std::vector<double> r_mm;             ///< r_k for every step ("predefined" mode) [mm]
  std::vector<double> ground_mm_s2;     ///< a_g,k for every step ("rths" mode) [mm/s^2]
};

/// At rest at k = 0, every vector sized once (x has one entry in "predefined" mode).
StructureState MakeState(const NumericalSubstructure& m);

/// Step k: x_k from x_{k-1}, x_{k-2}, a_g,k-1 and the force f_{k-1} [kN] measured at sample k-1
/// (Eq. 1 with Eqs. 2-3; nothing to integrate at k = 0), or x_k = r_k ("predefined"). Returns
/// r_k = x_k at the actuator [mm]. No allocation.
double Step(const NumericalSubstructure& m, StructureState* s, std::int64_t k, double f_prev_kN);

/// a_g,k [mm/s^2] (0 in "predefined" mode).
inline double GroundAt(const NumericalSubstructure& m, std::int64_t k) {
  return m.predefined() ? 0.0 : m.ground_mm_s2[static_cast<std::size_t>(k)];
}

}  // namespace rths::models
