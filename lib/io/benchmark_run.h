#pragma once
/// @file The RTHS benchmark's criteria J1-J9 of a run (signal/benchmark_criteria.h,
/// docs/benchmark.md): the monolithic reference structure (structure.reference_file) integrated
/// offline under the ground acceleration the run's log holds, against what the run logged.
///
/// Reference response: the same central difference as the integrator (models/structure.h, Eqs. 1-3)
/// at the run's dt, from rest, without a specimen, driven by desired_t.ground_acc_mm_s2 of each
/// logged step: x_r,0 = 0 and x_r,k+1 from x_r,k, x_r,k-1 and a_g,k, so x_r,k depends on a_g up to
/// k-1 exactly as the integrator's x_k does.
///
/// The criteria's records, per logged step k (io/run_signals.h column names, mm):
///     x_m = y_mm (measured_t.y_mm),  x_t = r_mm (desired_t.r_mm),
///     x_n,i = x<i>_mm (desired_t.x_mm[i-1]),  x_r,i = the reference response,
/// and the actuator's floor structure.actuator_dof. A run that stopped early is evaluated over the
/// steps its log holds.
#include <span>
#include <string>
#include <vector>

#include "io/run_log.h"
#include "io/run_signals.h"
#include "models/structure.h"
#include "scenario/scenario.h"
#include "signal/benchmark_criteria.h"

namespace rths::io {

/// The response x_r,k [mm] of `reference` (no specimen force) at dt_s [s] to the ground
/// acceleration a_g,k [mm/s^2], from rest: one row per sample k = 0..N-1 (N = ground's length),
/// x_r[i][k] for floor i + 1. Throws rths::Error if dt_s is at or above the central-difference
/// stability limit of `reference` (CentralDifference::Make).
std::vector<std::vector<double>> ReferenceResponse(const models::LinearStructure& reference, double dt_s,
                                                   std::span<const double> ground_acc_mm_s2);

/// The monolithic reference structure a scenario names (structure.reference_file, with its iota),
/// the specimen position at structure.actuator_dof (count 1; unused: no force). Throws
/// rths::Error naming "<scenario>: structure.reference_file" if the scenario has none, the file
/// does not load, or its DOF count differs from the run's.
models::LinearStructure ReferenceStructure(const scenario::Scenario& s, int run_dofs);

/// The criteria's records from a run's signals (columns y_mm, r_mm, ground_acc_mm_s2, x1_mm..xN_mm)
/// and its scenario (reference_file, actuator_dof), the reference integrated at signals.dt_s.
/// Throws rths::Error as ReferenceStructure, or if a column is missing.
signal::BenchmarkSignals BenchmarkSignalsFromRun(const RunSignals& signals, const scenario::Scenario& s);

/// BenchmarkCriteriaFrom(BenchmarkSignalsFromRun(signals, s)). Throws rths::Error (too few steps,
/// a diverged run, a reference floor that does not move, ...).
signal::BenchmarkCriteria BenchmarkCriteriaFromRun(const RunSignals& signals, const scenario::Scenario& s);

/// J1-J9 of the run whose log is `log` and whose scenario is `s`: its complete steps
/// (RunLog::CompleteSteps()) at s.run.dt_s. Throws rths::Error as BenchmarkCriteriaFromRun.
signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const RunLog& log, const scenario::Scenario& s);
/// The same from the log file at `log_path` (ReadRunLog; its errors name the file).
signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const std::string& log_path, const scenario::Scenario& s);

}  // namespace rths::io
