#pragma once
/// @file The step-index table of docs/lockstep.md as data: who answers what at step k, from which
/// messages. The roster (the roles every run has), every participant's step loop, its missing-input
/// list (repair), its wake-ups and the clock's barrier are derived from it (lockstep/wiring.h).
///
/// Nothing here names a transport: each role may be reached over its own (a process on udpm, the
/// in-process queue, an LCM instance of its own).
#include <array>
#include <cstdint>
#include <string_view>

#include "lockstep/protocol.h"

namespace rths::lockstep {

/// One input of a role's answer of step k: the message of step k + offset on `channel`. An input
/// of a step before 0 or at or after the run's last step does not exist (it is not waited for).
struct StepInput {
  Channel channel = kNoChannel;
  int offset = 0;
};

/// The variants of a row (RoleRow::variant).
inline constexpr std::string_view kIdealVariant = "ideal";
inline constexpr std::string_view kRecordedVariant = "recorded";
inline constexpr std::string_view kSameSampleVariant = "same_sample";

/// One row of the step-index table.
struct RoleRow {
  std::string_view role;
  /// "" for the role's ordinary row; otherwise the variant a run selects instead (Wiring::Resolve):
  /// "ideal" (plant.kind = "ideal": the plant answers desired_t k), "recorded" (a stand-in that
  /// answers step k with a recorded message once desired_t k requests it: `rths replay`),
  /// "same_sample" (the integrator answers desired_t k from measured_t k: the maRTHS benchmark).
  std::string_view variant;
  Channel answer = kNoChannel;
  /// What its answer of step k is computed from (in this order), handed to its step function.
  std::array<StepInput, 4> inputs{};
  /// The offsets b of its answers (step k + b) that the clock's barrier of step k waits for;
  /// none for the clock itself.
  std::array<int, 2> barrier{};
  int n_barrier = 0;
  /// The logger: its answer of step k also waits for every other role's barrier items of step k.
  bool acks_barrier = false;
  /// The clock: owns k; it answers step k (requests it) once the barrier of step k-1 is complete.
  bool clock = false;
  /// Place in an in-process group (memq): the logger subscribes before anyone publishes, the clock
  /// is built last.
  int build_rank = 0;

  int n_inputs() const {
    int n = 0;
    while (n < static_cast<int>(inputs.size()) && inputs[n].channel != kNoChannel) ++n;
    return n;
  }
};

/// docs/lockstep.md, "Time and indices" (rows in roster order; variants after their role).
inline constexpr std::array<RoleRow, 10> kStepTable{{
    // desired_t k from measured_t k-1 (f_{k-1}); issued when the barrier of step k-1 is complete.
    {"integrator", "", kDesired, {{{kMeasured, -1}}}, {}, 0, false, true, 4},
    // "same_sample": desired_t k from measured_t k (the forces of t_k, as the maRTHS reference code's
    // signal flow: docs/marths.md); measured_t k is in the barrier of step k-1; step 0 waits for
    // measured_t 0 (the plant's state at rest, sent at GO).
    {"integrator", kSameSampleVariant, kDesired, {{{kMeasured, 0}}}, {}, 0, false, true, 4},
    // command_t k (u_k) from desired_t k (r_k) and measured_t k (y_k).
    {"controller", "", kCommand, {{{kDesired, 0}, {kMeasured, 0}}}, {0}, 1, false, false, 2},
    {"controller", kRecordedVariant, kCommand, {{{kDesired, 0}}}, {0}, 1, false, false, 2},
    // measured_t k from u_{k-1}, i_{k-1} held over [t_{k-1}, t_k); measured_t 0 at rest, at GO.
    {"plant", "", kMeasured, {{{kCommand, -1}, {kCurrent, -1}}}, {0, 1}, 2, false, false, 1},
    // "ideal": measured_t k from desired_t k (y_k = r_k) and current_t k-1 (docs/lockstep.md, footnote).
    {"plant", kIdealVariant, kMeasured, {{{kDesired, 0}, {kCurrent, -1}}}, {0}, 1, false, false, 1},
    {"plant", kRecordedVariant, kMeasured, {{{kDesired, 0}}}, {0}, 1, false, false, 1},
    // current_t k (i_k) from desired_t k and measured_t k.
    {"semiactive", "", kCurrent, {{{kDesired, 0}, {kMeasured, 0}}}, {0}, 1, false, false, 3},
    {"semiactive", kRecordedVariant, kCurrent, {{{kDesired, 0}}}, {0}, 1, false, false, 3},
    // ack_t k: the four messages of step k are in log.lcm (and the rest of the barrier is in).
    {"logger", "", kAck, {{{kDesired, 0}, {kCommand, 0}, {kMeasured, 0}, {kCurrent, 0}}}, {0}, 1, true, false, 0},
}};

/// The roles every run has, in roster order (the GO message's roster): the table's ordinary rows.
inline constexpr int kRosterSize = [] {
  int n = 0;
  for (const RoleRow& r : kStepTable) n += r.variant.empty() ? 1 : 0;
  return n;
}();
inline constexpr std::array<std::string_view, kRosterSize> kRoster = [] {
  std::array<std::string_view, kRosterSize> out{};
  int n = 0;
  for (const RoleRow& r : kStepTable) {
    if (r.variant.empty()) out[n++] = r.role;
  }
  return out;
}();
/// The roster in build order of an in-process group (RoleRow::build_rank).
inline constexpr std::array<std::string_view, kRosterSize> kBuildOrder = [] {
  std::array<std::string_view, kRosterSize> out{};
  for (const RoleRow& r : kStepTable) {
    if (r.variant.empty()) out[r.build_rank] = r.role;
  }
  return out;
}();
/// The clock's role (the row with clock = true).
inline constexpr std::string_view kClockRole = [] {
  for (const RoleRow& r : kStepTable) {
    if (r.clock) return r.role;
  }
  return std::string_view{};
}();
/// Index of `role` in kRoster, or -1.
constexpr int RosterIndex(std::string_view role) {
  for (int i = 0; i < kRosterSize; ++i) {
    if (kRoster[i] == role) return i;
  }
  return -1;
}
/// The lcm-gen type of a per-step channel's message ("measured_t"; "" for an unknown code).
const char* MessageName(Channel channel);

}  // namespace rths::lockstep
