#pragma once
/// @file What a participant in follow mode (fed by `lcm-logplayer`, docs/replay.md) did with every
/// step of the recorded run: answered it exactly, answered it after an earlier step had to be held,
/// answered it from a held input, or never saw it. Printed and written at its exit.
#include <cstdint>
#include <utility>
#include <vector>

namespace rths::lockstep {

/// How a follow-mode participant answered one step.
enum class FollowStep : std::uint8_t {
  kUnseen = 0,   ///< not answered: nothing of it, or of a later step, arrived before the feed ended
  kExact = 1,    ///< every input of it and of every earlier step arrived: the recorded answer
  kResumed = 2,  ///< every input of it arrived, but an earlier step was held: its state may differ
  kHeld = 3,     ///< at least one input was lost and replaced by the one before it (zero-order hold)
};

/// The number of steps in each class; they add up to the run's steps.
struct FollowCounts {
  std::int64_t exact = 0;
  std::int64_t resumed = 0;
  std::int64_t held = 0;
  std::int64_t unseen = 0;
  std::int64_t total() const { return exact + resumed + held + unseen; }
  /// Every step answered with the recorded answer.
  bool all_exact() const { return resumed == 0 && held == 0 && unseen == 0; }
};

/// A run of consecutive steps [first, last] in one class.
using StepRange = std::pair<std::int64_t, std::int64_t>;

/// One class per step of the run. Sized before the feed starts (allocates); Mark allocates nothing.
class FollowLedger {
 public:
  /// n_steps steps, all unseen.
  void Size(std::int64_t n_steps) { steps_.assign(static_cast<std::size_t>(n_steps > 0 ? n_steps : 0), FollowStep::kUnseen); }
  /// Step k was answered; `held`: from at least one held input. An answer from complete inputs is
  /// exact until the first held step, resumed after it.
  void Mark(std::int64_t k, bool held) {
    if (k < 0 || k >= static_cast<std::int64_t>(steps_.size())) return;
    held_before_ = held_before_ || held;
    steps_[static_cast<std::size_t>(k)] = held ? FollowStep::kHeld : held_before_ ? FollowStep::kResumed : FollowStep::kExact;
  }
  /// A message of the run arrived (on a channel it reads).
  void Heard() { ++messages_; }
  /// Messages of the run that arrived.
  std::int64_t messages() const { return messages_; }
  FollowStep at(std::int64_t k) const { return steps_.at(static_cast<std::size_t>(k)); }
  std::int64_t n_steps() const { return static_cast<std::int64_t>(steps_.size()); }
  FollowCounts Counts() const;
  /// The runs of consecutive steps of class `c`, in step order.
  std::vector<StepRange> Ranges(FollowStep c) const;

 private:
  std::vector<FollowStep> steps_;
  bool held_before_ = false;
  std::int64_t messages_ = 0;
};

}  // namespace rths::lockstep
