#pragma once
/// @file A run's wiring, resolved from the step table (lockstep/step_table.h) and checked before the
/// run starts: for every role, the row it runs, the messages its step k waits for, which of them
/// wake it, and what it lacks when the clock re-requests a step.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "lockstep/step_table.h"
#include "lockstep/want_list.h"

namespace rths::lockstep {

/// One role of a run, resolved.
struct ResolvedRole {
  const RoleRow* row = nullptr;
  /// Every message its step k waits for: the row's inputs; the logger adds the other roles'
  /// barrier items of step k; the clock's are the barrier of step k-1.
  std::array<StepInput, WantList::kCapacity> waits{};
  int n_waits = 0;
  /// Whether waits[i] is one that wakes it: no other input of its step k follows from it.
  std::array<bool, WantList::kCapacity> wakes_for{};
  std::array<bool, kChannelCodes> reads{};  ///< it subscribes to this channel
  /// Whether a message on the channel wakes it: the channel of one of its wakes_for inputs
  /// (docs/lockstep.md, "Wake-ups").
  std::array<Wake, kChannelCodes> wake{};

  std::string_view role() const { return row->role; }
  /// The largest barrier offset of its answer (the plant: measured_t k+1 is in the barrier of k).
  int max_barrier_offset() const;
  /// Whether its input (channel, j) is one its step k waits for (j = k + offset, 0 <= j < n_steps).
  bool Waits(Channel channel, std::int64_t j, std::int64_t k) const;
};

/// Which row a role runs when not its ordinary one ("" = ordinary).
struct RoleVariant {
  std::string_view role;
  std::string_view variant;
};

class Wiring {
 public:
  /// Resolves the roster with the given variants (e.g. {"plant", "ideal"}) and checks it: every
  /// variant exists; every input is some role's answer and each answer has one owner; the
  /// dependencies within and across steps are acyclic (within 3 steps); every role but the clock
  /// has a wake-up input. Throws rths::Error naming what is wrong.
  static Wiring Resolve(const std::vector<RoleVariant>& variants = {});

  const ResolvedRole& Of(std::string_view role) const;  ///< throws rths::Error for an unknown role
  /// The clock's row (its index is known at compile time: no lookup on the step's path).
  const ResolvedRole& Clock() const {
    constexpr int kClock = RosterIndex(kClockRole);
    static_assert(kClock >= 0, "the roster has a clock");
    return roles_[kClock];
  }
  const std::array<ResolvedRole, kRosterSize>& roles() const { return roles_; }
  /// The roster's non-clock roles in the order of the step (by how many messages of the step
  /// their answer follows from; ties in roster order): whom a stalled step blames first.
  const std::array<int, kRosterSize - 1>& step_order() const { return step_order_; }
  /// The table as docs/lockstep.md prints it (one line per role: answer, inputs, wakes, barrier).
  std::string Describe() const;

 private:
  std::array<ResolvedRole, kRosterSize> roles_{};
  std::array<int, kRosterSize - 1> step_order_{};
};

}  // namespace rths::lockstep
