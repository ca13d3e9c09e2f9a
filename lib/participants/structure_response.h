#pragma once
/// @file What a yielding numerical substructure did in a run (summary.json's
/// structure_peak_displacement_mm, structure_residual_displacement_mm,
/// structure_hysteretic_energy_kN_mm; docs/structures.md "Nonlinear stories").
///
/// From the run's log and scenario, after the run: the displacements are the logged x_k
/// (desired_t.x_mm, what the integrator commanded); the hysteretic energy is the integrator's own,
/// replayed offline (models::Simulate of the same models::StructureIntegrator under the scenario's
/// ground record and the logged forces f_k, measured_t.f_kN, as the integrator received them), so it
/// needs nothing in the log beyond what every run writes. The replay's last displacement must equal
/// the logged one bit for bit (else it throws: the scenario given is not the run's), which is what
/// makes its energy the run's.
#include <string>

#include "io/run_log.h"
#include "scenario/scenario.h"

namespace rths::participants {

struct StructureResponse {
  int floor = 1;                        ///< the floor the displacements are of (the top one), 1-based
  double peak_displacement_mm = 0.0;    ///< max_k |x_k| at that floor, relative to the ground [mm]
  double residual_displacement_mm = 0.0;  ///< x at the last logged step [mm]
  double hysteretic_energy_kN_mm = 0.0;   ///< dissipated by every story spring by then [kN mm]
  /// The story whose peak drift is the largest multiple of its spring's yield drift (of the
  /// largest drift if no story yields), 1-based, its peak drift max_k |x_i - x_i-1| [mm] and that
  /// multiple, the peak ductility (0 if every story is linear).
  int story = 1;
  double peak_drift_mm = 0.0;
  double ductility = 0.0;
};

/// The response of the run logged in `log` (its complete steps) whose scenario is `s`, whose
/// structure is stepped (StructureConfig::Stepped()). Throws rths::Error for another structure or
/// a log without complete steps.
StructureResponse StructureResponseOfRun(const io::RunLog& log, const scenario::Scenario& s);

}  // namespace rths::participants
