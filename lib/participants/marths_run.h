#pragma once
/// @file The maRTHS benchmark's evaluation of a lockstep run (marths.enabled; docs/marths.md): J1-J10
/// of S5_Evaluation.m (signal/marths_criteria.h) and its "realizable" check, from what the run
/// logged, with the reference structure integrated offline under the same ground motion.
///
/// The criteria's records, per complete logged step k:
///     x_a,i = desired_t.r_act_mm[i],  x_m,i = measured_t.y_act_mm[i],
///     (x_hat, theta_hat) = the coupler's inverse (marths.inverse) of the logged strokes,
///     numerical substructure = desired_t.x_mm / 1000 (its 29 DOFs' displacements),
///     reference structure = Newmark of the 29-DOF reference under a_g(t_k) (participants::MarthsGroundOf),
/// and the commands' voltages from command_t.u_act_mm (signal::MarthsVoltage).
/// In participants, below the users: the run summary (supervisor/run_summary.h) scores every such run.
#include <string>

#include "io/run_log.h"
#include "scenario/scenario.h"
#include "signal/marths_criteria.h"

namespace rths::participants {

/// A run's score.
struct MarthsRunScore {
  signal::MarthsCriteria j;
  double max_volts[2] = {0.0, 0.0};  ///< largest |command| per actuator [V]
  /// S5_Evaluation.m: not realizable when both actuators' largest |V| exceed signal::kMarthsVoltLimit.
  bool realizable = true;
  std::int64_t steps = 0;  ///< the complete steps scored
};

/// The score of the run whose log is `log` and whose scenario is `s` (marths.enabled), over its
/// complete steps. Throws rths::Error for a scenario without [marths], a log whose messages do not
/// carry two actuators, or too few steps (signal::MarthsCriteriaFrom's errors).
MarthsRunScore MarthsScoreOfRun(const io::RunLog& log, const scenario::Scenario& s);

}  // namespace rths::participants
