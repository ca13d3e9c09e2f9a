#pragma once
/// @file The shipped maRTHS scenarios (scenarios/marths/elcentro_{none,rodeac,ff,ff_lqg}.toml) run
/// through the lockstep, in this process (memq), scored from their logs (participants/marths_run.h)
/// and set beside the in-process loop's nominal runs of `rths reproduce marths` (docs/marths.md
/// "Through the lockstep").
#include <cstdint>
#include <string>
#include <vector>

#include "signal/marths_criteria.h"
#include "studies/marths.h"
#include "studies/study.h"

namespace rths::studies {

/// One shipped scenario's run.
struct MarthsLockstepRow {
  std::string compensator;
  std::int64_t steps = 0;
  signal::MarthsCriteria lockstep;  ///< from the run's log
  signal::MarthsCriteria loop;      ///< the study's nominal run of the same compensator
  double max_rel_diff = 0.0;        ///< the largest |lockstep - loop| / |loop| over J1-J10
  double max_volts[2] = {0.0, 0.0};
  bool realizable = true;
  double wall_s = 0.0;              ///< the lockstep run's wall time [s]
};

/// Runs each shipped scenario for `samples` steps (the study's record length: the whole record, or
/// --quick's first 20 s) and compares it with `rows`' nominal run. Logs go to a temporary folder,
/// removed after scoring. Throws rths::Error for a scenario that does not load or a run that fails.
std::vector<MarthsLockstepRow> RunMarthsScenarios(const ReproduceOptions& opts, const std::vector<MarthsRow>& rows,
                                                  std::size_t samples, double dt_s);

}  // namespace rths::studies
