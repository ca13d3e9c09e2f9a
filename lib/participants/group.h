#pragma once
/// @file All five participants of a run in this process, on one memq:// LCM instance: what
/// `rths run --transport memq` does, and what the reproduction studies and tests use to run
/// many groups side by side (each group has its own instance, so they cannot cross-talk).
#include <string>
#include <string_view>
#include <vector>

#include "lockstep/runtime.h"
#include "scenario/scenario.h"

namespace rths::participants {

/// Order the group is built in: the logger subscribes before anyone publishes.
inline constexpr std::string_view kGroupOrder[] = {"logger", "plant", "controller", "semiactive",
                                                   "integrator"};

/// A test-only fault for one role.
struct RoleFault {
  std::string role;
  lockstep::Faults faults;
};

/// How one participant ended.
struct Outcome {
  std::string role;
  int exit_code = 0;     ///< lockstep::ExitCode, or 128 + signal for a process
  int signal = 0;        ///< the signal that killed the process (0 if none)
  std::string message;   ///< why it failed ("" if it did not)
};

/// Runs a whole group on memq://; `out_dir` receives log.lcm and signals.csv. `per_role` holds
/// one scenario for every role, or five, in kGroupOrder (tests give one role another file).
/// Throws rths::Error if a participant cannot be built (bad model, unwritable output).
std::vector<Outcome> RunGroupInProcess(const std::vector<scenario::Scenario>& per_role,
                                       std::int64_t run_id, const std::string& out_dir,
                                       const std::vector<RoleFault>& faults = {});

/// The outcome to blame for a failed run: one that failed on its own (a signal, an exception)
/// before one that detected a failure (lockstep) before one that was told to stop; nullptr if
/// every participant succeeded.
const Outcome* RootCause(const std::vector<Outcome>& outcomes);

}  // namespace rths::participants
