#pragma once
/// @file The RTHS benchmark's closed loop in one process, closed either as our lockstep testbed
/// closes it or as the benchmark's reference code does (Silva et al. 2020; its Simulink model
/// vRTHS_MDOF_SimRT2014a.slx, package MECHS-RCN/BENCHMARKS "RTHS code RT V23"), so that what each
/// difference changes in J1-J9 can be measured by switching it alone (docs/benchmark.md, "How the
/// loop is closed").
///
/// Common to both: the plant Gp as procs/plant runs it (models::MakeRig: the exact ZOH of the
/// command, the load cell, the sensor noise drawn y then f per sample from plant.noise_seed), the
/// controller as procs/controller runs it (control::MakeTrackingController, its derivatives from
/// control::StepDerivatives as the integrator computes them), the sample k -> k+1:
///
///     r_k = x_n,a(t_k);   y_k, f_k = readings at t_k;   u_k = controller(r_k, y_k);
///     plant: u_k held over [t_k, t_{k+1});   substructure: t_k -> t_{k+1} with f_{k-d}.
///
/// The switches:
///  - substructure: "cd", the integrator's central difference (Eqs. 1-3), x_{k+1} from x_k, x_{k-1},
///    a_g(t_k) and f_{k-d}; or "rk4", the reference code's fixed-step ode4 on the continuous
///    substructure, M_n x'' + C_n x' + K_n x = -M_n iota a_g(t) - e_a f_{k-d}, with f held over the
///    step and a_g(t) the record's linear interpolation (Simulink's From File) at t_k, t_k + dt/2,
///    t_k + dt;
///  - force_delay_steps d: 0 (the lockstep's x_{k+1} uses f_k) or 1 (the reference code's Unit
///    Delay on the measured force);
///  - reference: the monolithic structure by "cd" (models::GroundResponse, as rths run scores) or by
///    "rk4" (continuous, as the reference code's lsim);
///  - quantise_m: the reference code's converters around its example controller (`lti` only): its
///    target, the reference filter's output, the error and the command each rounded to a multiple
///    of quantise_m metres (2^-18 m in the reference code; 0: off).
/// With substructure = reference = "cd", d = 0 and no quantisation the loop is the lockstep run's,
/// step for step (tests/studies/benchmark_loop_test.cpp checks J1-J9 against a memq run of the scenario).
#include <string>

#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"

namespace rths::studies {

enum class LoopIntegration { kCentralDifference, kRk4 };

/// How the loop is closed (see the file comment).
struct LoopOptions {
  LoopIntegration substructure = LoopIntegration::kCentralDifference;
  int force_delay_steps = 0;  ///< 0 or 1
  LoopIntegration reference = LoopIntegration::kCentralDifference;
  double quantise_m = 0.0;    ///< converter step [m]; 0: none
  std::string Label() const;  ///< e.g. "rk4, force delay 1, reference rk4, quantised 2^-18 m"
};

/// The loop as the lockstep testbed closes it; and as the reference code does.
LoopOptions LockstepLoop();
LoopOptions ReferenceCodeLoop();

struct LoopResult {
  signal::BenchmarkCriteria j;
  std::int64_t steps = 0;
  double peak_u_mm = 0.0;  ///< max |u_k|
};

/// Runs scenario `s` (structure.mode "rths", kind "file" with a reference_file, plant.kind
/// "benchmark") through the loop `o` for s.steps() samples and scores it. Reads the scenario's
/// structure, reference and ground-motion files (paths as the scenario holds them). Throws
/// rths::Error naming the key for a scenario it cannot run, or if the loop diverges.
LoopResult RunBenchmarkLoop(const scenario::Scenario& s, const LoopOptions& o);

}  // namespace rths::studies
