#pragma once
/// @file Which integrator steps the numerical substructure, and its options (structure.integrator,
/// docs/structures.md "Integrators"): plain config, parsed by the scenario, validated here.
#include <array>

#include "core/names.h"

namespace rths::models {

enum class IntegratorKind { kCentralDifference, kCr, kAlphaOs, kNewmarkImplicit, kRk4UnitDelay };
inline constexpr std::array<Named<IntegratorKind>, 5> kIntegratorKindNames = {
    {{IntegratorKind::kCentralDifference, "central_difference"},
     {IntegratorKind::kCr, "cr"},
     {IntegratorKind::kAlphaOs, "alpha_os"},
     {IntegratorKind::kNewmarkImplicit, "newmark_implicit"},
     {IntegratorKind::kRk4UnitDelay, "rk4_unit_delay"}}};

/// Plain config (structure.integrator and its options).
struct IntegratorConfig {
  /// central_difference (Eqs. 1-3) | cr (Chen & Ricles 2008) | alpha_os (Combescure & Pegon 1997)
  /// | newmark_implicit (average acceleration, fixed Newton iterations) | rk4_unit_delay (the RTHS
  /// benchmark's reference-code loop, linear structures only).
  IntegratorKind kind = IntegratorKind::kCentralDifference;
  /// central_difference, cr: numerical steps per RTHS step [1, 1000] (force held, ground
  /// interpolated); 1 for the others.
  int substeps = 1;
  double alpha = -0.05;        ///< alpha_os: [-1/3, 0]
  int newton_iterations = 2;   ///< newmark_implicit: [1, 100]
  /// Throws rths::Error(field, "must be ...") naming the field and its range.
  void Validate() const;
  bool operator==(const IntegratorConfig&) const = default;
};

}  // namespace rths::models
