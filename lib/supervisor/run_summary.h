#pragma once
/// @file What one run's summary.json holds, for `rths run` and for every run of a reproduction:
/// filled from the participants' outcomes and the run's log, written once (ToJson), and printed
/// from the struct (Report), never re-read from the file.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "core/exit_code.h"
#include "lockstep/link_stats.h"
#include "participants/group.h"
#include "participants/marths_run.h"
#include "scenario/scenario.h"
#include "participants/structure_response.h"
#include "signal/benchmark_criteria.h"

namespace rths::supervisor {

using participants::Outcome;
using participants::Verdict;

struct RunSummary {
  std::string label;              ///< a reproduction's run label ("" for `rths run`)
  std::string scenario;           ///< the scenario file the run used
  std::string scenario_sha256;
  std::int64_t run_id = 0;
  std::string transport;          ///< "memq" or "udpm"
  std::string lcm_url;            ///< udpm: the run's URL ("" for memq)
  std::int64_t steps_expected = 0;
  double wall_s = 0.0;            ///< [s] start to end, set-up and teardown included
  std::int64_t output_estimate_bytes = 0;  ///< `rths run`: output estimated before the run (0: none)

  // From the log (ReadLog): whatever was committed, even after a failure.
  std::int64_t steps = 0;         ///< complete steps in the log
  std::optional<io::RunMetrics> metrics;  ///< Eq. 31 error, peaks, extrapolation errors (if the log was read)
  std::int64_t duplicates_logged = 0;     ///< duplicate events in the log, all channels
  std::string log_error;          ///< why the log could not be read ("" if it could)
  /// The RTHS benchmark's J1-J9 over the logged steps (raw values), when the scenario has a
  /// structure.reference_file (ReadLog with the scenario; participants/benchmark_run.h).
  std::optional<signal::BenchmarkCriteria> benchmark_criteria;
  std::string benchmark_error;    ///< why they could not be computed ("" if they were or were not asked for)
  /// The maRTHS benchmark's J1-J10 and realizable verdict over the logged steps, when the scenario has
  /// marths.enabled (participants/marths_run.h); marths_error says why not.
  std::optional<participants::MarthsRunScore> marths;
  std::string marths_error;
  /// A stepped (yielding) structure's response (participants/structure_response.h), or why not.
  std::optional<participants::StructureResponse> structure_response;
  std::string structure_error;

  // From the outcomes (SetOutcomes, SetVerdict).
  double stepping_s = 0.0;        ///< [s] the clock's GO to its last committed step
  std::string status = "completed";  ///< completed | interrupted | stopped by the safety monitor |
                                     ///< stopped by the miss policy | aborted (an ABORT from outside
                                     ///< the group, e.g. the monitor's button) | failed
  int exit_code = 0;              ///< the run's exit code (ExitCode (core/exit_code.h), 130 interrupted, 128 + signal)
  std::string stopped = "no";     ///< "no", or why the run stopped
  struct Failure {
    std::string participant;      ///< whom the verdict blames
    std::int64_t step = -1;       ///< the step it happened at (-1 if unknown)
    std::string what;
    int exit_code = 0;
    std::optional<double> teardown_s;  ///< [s] from noticing the failure to the group's end
  };
  std::optional<Failure> failure;
  lockstep::LinkStats link;       ///< every participant's link statistics, summed
  /// Paced runs: the clock's latency figures (RealtimeToJson) plus what each process got of
  /// SCHED_FIFO / mlockall; null when the run was not paced.
  nlohmann::json realtime;
  std::vector<Outcome> participants;  ///< how each participant ended

  /// Steps per second of the clock's stepping time (0 if unknown).
  double steps_per_s() const;
  nlohmann::json ToJson() const;
  /// The terminal lines after a run (steps, Eq. 31 error, peak force, rate, the benchmark's J1-J9
  /// if computed, real-time figures, link repairs); dt_s [s] turns the rate into a multiple of real
  /// time.
  std::string Report(double dt_s) const;
};

/// Sets steps, metrics and duplicates_logged from the run's log at `log_path`, or log_error
/// (steps 0) if it cannot be read.
void ReadLog(const std::string& log_path, RunSummary* s);
/// ReadLog, then, if `scenario` has a structure.reference_file, the benchmark's J1-J9 over the
/// log's complete steps (BenchmarkCriteriaOfRun) into benchmark_criteria, or why not into
/// benchmark_error (too few steps, a diverged run, ...; never thrown); and for a stepped structure
/// (a hysteretic spring, cr, alpha_os, newmark_implicit) its response into structure_response, or
/// why not into structure_error.
void ReadLog(const std::string& log_path, const scenario::Scenario& scenario, RunSummary* s);

/// Sets participants, stepping_s (the clock's) and link (summed over the participants whose
/// statistics are known).
void SetOutcomes(const std::vector<Outcome>& outcomes, RunSummary* s);

/// Sets status, exit_code, stopped and failure from the group's verdict. A process that died
/// cannot say where: its step is then the first one the log does not hold (call ReadLog first).
void SetVerdict(Verdict verdict, bool interrupted, RunSummary* s);

}  // namespace rths::supervisor
