#pragma once
/// @file The RTHS benchmark's criteria J1-J9 of a run (signal/benchmark_criteria.h,
/// docs/benchmark.md): the monolithic reference structure (structure.reference_file) integrated
/// offline under the ground acceleration the run's log holds, against what the run logged.
///
/// In participants, below the users: the run summary that scores every such run with it
/// (supervisor/run_summary.h), the run report and the benchmark study.
///
/// Reference response: models::GroundResponse (models/ground_response.h) at the run's dt, driven by
/// desired_t.ground_acc_mm_s2 of each logged step; for structure.integrator = "rk4_unit_delay" (the
/// reference code's loop) models::GroundResponseRk4, continuous as the reference code's lsim, with
/// a_g at the half steps from the scenario's ground record.
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

namespace rths::participants {

/// The monolithic reference structure a scenario names (structure.reference_file, with its iota),
/// the specimen position at structure.actuator_dof (count 1; unused: no force). Throws
/// rths::Error naming "<scenario>: structure.reference_file" if the scenario has none, the file
/// does not load, or its DOF count differs from the run's.
models::LinearStructure ReferenceStructure(const scenario::Scenario& s, int run_dofs);

/// The criteria's records from a run's signals (columns y_mm, r_mm, ground_acc_mm_s2, x1_mm..xN_mm)
/// and its scenario (reference_file, actuator_dof), the reference integrated at signals.dt_s.
/// Throws rths::Error as ReferenceStructure, or if a column is missing.
signal::BenchmarkSignals BenchmarkSignalsFromRun(const io::RunSignals& signals, const scenario::Scenario& s);

/// BenchmarkCriteriaFrom(BenchmarkSignalsFromRun(signals, s)). Throws rths::Error (too few steps,
/// a diverged run, a reference floor that does not move, ...).
signal::BenchmarkCriteria BenchmarkCriteriaFromRun(const io::RunSignals& signals, const scenario::Scenario& s);

/// J1-J9 of the run whose log is `log` and whose scenario is `s`: its complete steps
/// (io::RunLog::CompleteSteps()) at s.run.dt_s. Throws rths::Error as BenchmarkCriteriaFromRun.
signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const io::RunLog& log, const scenario::Scenario& s);
/// The same from the log file at `log_path` (io::ReadRunLog; its errors name the file).
signal::BenchmarkCriteria BenchmarkCriteriaOfRun(const std::string& log_path, const scenario::Scenario& s);

}  // namespace rths::participants
