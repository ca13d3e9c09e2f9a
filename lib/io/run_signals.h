#pragma once
/// @file Every per-step signal of a run as named columns with units and one-line descriptions,
/// decoded from its log (io/run_log.h). One table for every consumer: `rths export` (.mat, CSV),
/// `rths report` (figures), tests. Column names follow the logger's signals.csv where a column
/// exists there (k, t_s, r_mm, u_mm, u_ff_mm, u_fb_mm, y_mm, e_mm, f_kN, i_cmd_A, i_eff_A,
/// ground_acc_mm_s2) and the message fields (lcmtypes/*.lcm) otherwise.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/run_log.h"

namespace rths::io {

/// One per-step signal of a run.
struct SignalColumn {
  std::string name;         ///< e.g. "r_mm", "y_mm", "f_kN", "x1_mm"  (same names as the logger's signals.csv where one exists)
  std::string unit;         ///< "mm", "mm/s", "mm/s^2", "mm/s^3", "kN", "A", "s", "" (step index)
  std::string description;  ///< one line, e.g. "desired actuator displacement r_k (Eq. 20-22 predictions in rd/rdd/rddd)"
  std::vector<double> values;
};

/// Every per-step signal of a run's complete steps 0..n-1 (RunLog::CompleteSteps()).
struct RunSignals {
  double dt_s = 0.0;
  /// k, t_s first; then the desired_t fields (r_mm, rd_mm_s, rdd_mm_s2, rddd_mm_s3,
  /// acc_prev_mm_s2, vel_prev_mm_s, ground_acc_mm_s2, x1_mm..xN_mm, abs_acc1_mm_s2..abs_accN_mm_s2),
  /// the command_t fields (u_mm, u_ff_mm, u_fb_mm), the measured_t fields (y_mm, then
  /// e_mm = r - y, f_kN, i_eff_A), the current_t fields (i_cmd_A, f_desired_kN) and, for an
  /// adaptive controller, its coefficients (a0, a1_s, a2_s2, a3_s3 from command_t.adapt); with
  /// several actuators, r_act<i>_mm, u_act<i>_mm, y_act<i>_mm per actuator and f_iface<i>.
  std::vector<SignalColumn> columns;
  /// Number of steps (rows): the length of every column (0 if there are no columns).
  std::size_t steps() const;
  const SignalColumn* Find(std::string_view name) const;  ///< nullptr if absent
  const SignalColumn& At(std::string_view name) const;    ///< throws rths::Error naming the column
};

/// The signals of `log`'s complete steps 0..CompleteSteps()-1; t_s = k dt_s. N (the structure's
/// degrees of freedom) is desired_t.n_dof of step 0 (0 columns if there is no complete step).
/// Throws rths::Error (where = log.source) if dt_s is not finite and > 0, or if a step's n_dof
/// differs from step 0's.
RunSignals SignalsFromRunLog(const RunLog& log, double dt_s);

/// The signals of run_dir/log.lcm (ReadRunLog) at the step its handshake carries (RunLog::StepS()).
/// Throws rths::Error naming the file if it cannot be read or no handshake carries dt_s.
RunSignals ReadRunSignals(const std::filesystem::path& run_dir);

}  // namespace rths::io
