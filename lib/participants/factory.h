#pragma once
/// @file Builds any participant of a run by role name, for a process (udpm) or for the
/// in-process group (memq), and the standard main() of a participant process.
#include <memory>
#include <string>
#include <string_view>

#include "lockstep/config.h"
#include "lockstep/faults.h"
#include "lockstep/participant.h"
#include "lockstep/wiring.h"
#include "scenario/scenario.h"

namespace rths::participants {

/// What the handshake compares, from a loaded scenario.
lockstep::RunIdentity IdentityOf(const scenario::Scenario& s, std::int64_t run_id);
/// Lockstep knobs: the scenario's [lockstep] table, with the clock's pacing from [realtime].
lockstep::LockstepConfig LockstepOf(const scenario::Scenario& s);
/// The run's wiring (lockstep/wiring.h), checked: the step table with the plant's "ideal" row when
/// plant.kind = "ideal" (it answers desired_t k with measured_t k). Throws rths::Error.
lockstep::Wiring WiringOf(const scenario::Scenario& s);
/// The faults of the scenario's [faults] table that `role` is subject to (the network faults
/// apply to every participant, the process fault to its role only).
lockstep::Faults FaultsOf(const scenario::Scenario& s, std::string_view role);

/// Builds the participant `role` on `lcm` (nullptr: attach it to a transport later), wired by
/// `wiring`, subject to `faults`. The logger writes `out_dir`/log.lcm and `out_dir`/signals.csv.
/// Throws rths::Error (unknown role, bad model, unwritable output).
std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir, lockstep::Faults faults,
                                                       const lockstep::Wiring& wiring);
/// As above, with WiringOf(s).
std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir, lockstep::Faults faults);
/// As above, with FaultsOf(s, role).
std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir);

/// Checks the run's wiring and builds every participant but the logger once, off-line, and throws
/// away: a scenario whose models cannot be built (a structure file with errors, a design that
/// fails) is refused before any process starts. Throws rths::Error.
void CheckBuildable(const scenario::Scenario& s);

/// lockstep::CheckMulticastRoute() and, if the host has no multicast route, what to run instead
/// (`./rths run --transport memq`); "" if the route is there.
std::string MulticastRouteAdvice();

/// What a run of `s` stores [bytes]: log.lcm (every step) and signals.csv (every run.csv_every-th
/// step; an upper bound per row). For the disk-space check and the size said before a run.
struct OutputBytes {
  double log = 0.0, csv = 0.0;
  double total() const { return log + csv; }
};
OutputBytes EstimateOutputBytes(const scenario::Scenario& s);
/// Bytes of log.lcm per step of a run of `s` (LogBytesPerStep with its message sizes).
std::int64_t LogBytesPerStepOf(const scenario::Scenario& s);

/// main() of procs/<role>: `--scenario FILE --lcm-url URL --run-id N [--out DIR]`.
/// Exit codes: ExitCode (core/exit_code.h). At exit it writes `DIR/logs/<role>.json` (its outcome and
/// link statistics, participants::OutcomeToJson) for the supervisor.
int RoleMain(std::string_view role, int argc, char** argv);

}  // namespace rths::participants
