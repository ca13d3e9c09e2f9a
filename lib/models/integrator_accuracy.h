#pragma once
/// @file The measured accuracy of the structural integrators (docs/structures.md, "Measured
/// accuracy"): each integrator at the RTHS step dt and at dt/2, dt/4 against the CVODE reference
/// (structure_reference.h) of the same building and record, with the order of convergence the
/// errors give. Used by tests/models/integrator_accuracy_test.cpp and bench-nonlinear_structure.
#include <functional>
#include <string>
#include <vector>

#include "models/nonlinear_building.h"
#include "models/structure_integrator.h"
#include "models/structure_reference.h"

namespace rths::models {

/// The issue-44 reference SDOF: 20 000 kg, 5 Hz at the initial stiffness (k = m (2 pi 5)^2 =
/// 19.74 kN/mm), C = 2 zeta m w with zeta = 0.02 at the initial stiffness, a Bouc-Wen spring with
/// alpha = 0.1, x_y = 4 mm, n = 1, beta = gamma = 0.5 (A = 1). No specimen force is applied
/// (specimen_count is 1 here because the model needs one; the runs pass f = 0).
NonlinearBuilding ReferenceSdof();

/// El Centro NS (data/ground_motion/elcentro_1940_ns_g.txt, 0.02 s rows, in g) x scale at g =
/// 9.81 m/s^2, linearly interpolated to step dt_s [s], duration_s long (zeros after the record)
/// [mm/s^2]. start_s > 0 delays it, ramping from zero over the file step before its first row
/// (signal::LoadHistory); with start_s = 0 the record starts at its first row, 0.0063 g at t = 0.
/// Throws rths::Error if the file cannot be read.
std::vector<double> ElCentroGround(const std::string& path, double scale, double dt_s, double duration_s,
                                   double start_s = 0.0);

/// One integrator at one step.
struct AccuracyRow {
  std::string integrator;        ///< name with its options, e.g. "cr", "alpha_os(-0.05)", "cd x2"
  double dt_s = 0.0;
  ResponseSummary summary;       ///< of the commands at the RTHS samples
  double hysteretic_energy_kN_mm = 0.0;
  double nrmse_pct = 0.0;        ///< roof displacement vs the reference at the RTHS samples [%]
  double max_error_mm = 0.0;     ///< max |x_roof - reference| at those samples [mm]
  double order = 0.0;            ///< log2(nrmse(2 dt) / nrmse(dt)); 0 on the coarsest row
  double max_residual_kN = 0.0;  ///< newmark_implicit: the largest residual left [kN]
};

struct AccuracyStudy {
  ReferenceSolution reference;   ///< at the RTHS step
  ResponseSummary reference_summary;
  std::vector<AccuracyRow> rows; ///< per config: dt, dt/2, ... (levels rows each)
};

/// A history sampled at step h [s] (one sample per step).
using SampledHistory = std::function<std::vector<double>(double h_s)>;

/// Runs every config at dt_s / 2^j, j = 0 .. levels - 1, on ground(dt) (a record sampled at step
/// dt [mm/s^2], the same continuous record at every step) and, if given, the specimen force
/// force(dt) [kN] (e.g. a run's measured force, ResampleLinear), against the reference at dt_s
/// (SolveReference at rtol, the force linear between its samples).
/// Throws what the integrators and the reference throw.
AccuracyStudy MeasureAccuracy(const NonlinearBuilding& b, double dt_s, const SampledHistory& ground, int levels,
                              const std::vector<IntegratorConfig>& configs, const SampledHistory& force = {},
                              double rtol = 1e-12);

/// samples [any unit] at step dt_s, linear between them, at step dt_s / r (r >= 1 an integer):
/// samples.size() * r values, the last sample held after the end. Throws rths::Error for r < 1.
std::vector<double> ResampleLinear(const std::vector<double>& samples, int r);

/// A short name of a config: "central_difference", "cr x4" (4 sub-steps), "alpha_os(-0.05)",
/// "newmark_implicit(2 it)".
std::string Describe(const IntegratorConfig& c);

}  // namespace rths::models
