#pragma once
/// @file Fault injection on a participant's receive path (the scenario's [faults] table,
/// docs/lockstep.md "Fault injection"): drop, duplicate, delay or reorder a seeded random
/// fraction of the messages each participant receives, on every channel (handshake included),
/// to rehearse a lossy link; and process faults (a participant that stalls, throws, crashes, is
/// killed or stopped at a given step). Off by default; a run with faults must end bit-identical
/// to a clean one (per (channel, k) payload) or stop naming the faulty participant.
#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/names.h"

namespace rths::lockstep {

/// What a process fault does at its step.
enum class ProcessFault {
  kNone,
  kStall,  ///< stops answering from the step on (a hung computation; the process stays alive)
  kThrow,  ///< an exception in the step computation (exit 5, ABORT broadcast)
  kCrash,  ///< abort(): dies by SIGABRT (udpm only)
  kKill,   ///< raise(SIGKILL), as `kill -9` from outside (udpm only)
  kStop,   ///< raise(SIGSTOP), as `kill -STOP`; continued after stop_s if stop_s > 0 (udpm only)
};
inline constexpr std::array<Named<ProcessFault>, 5> kProcessFaultNames = {
    {{ProcessFault::kStall, "stall"},
     {ProcessFault::kThrow, "throw"},
     {ProcessFault::kCrash, "crash"},
     {ProcessFault::kKill, "kill"},
     {ProcessFault::kStop, "stop"}}};

/// Fault injection, off by default (docs/lockstep.md "Fault injection"): seeded random faults
/// on every message each participant receives, and one process fault.
struct FaultConfig {
  double drop = 0.0;           ///< fraction of received messages lost, [0, 0.5]
  double duplicate = 0.0;      ///< fraction delivered twice, [0, 0.5]
  double delay = 0.0;          ///< fraction delivered up to delay_ms late, [0, 0.5]
  double reorder = 0.0;        ///< fraction delivered after the next message, [0, 0.5]
  double delay_ms = 20.0;      ///< longest delay [ms], (0, 10000]
  std::int64_t seed = 1;       ///< [0, 2^53]
  /// udpm: each participant's UDP receive buffer [bytes] (LCM's recv_buf_size; 0 = the host's
  /// default), 0 or [1024, 2^27]: a small one loses messages in bursts.
  std::int64_t recv_buf_bytes = 0;
  /// [faults.process]: one participant stalls, throws, crashes, is killed or stopped at a step.
  std::string process_role;    ///< "" (none) or a participant: integrator, controller, plant, semiactive, logger
  ProcessFault process_kind = ProcessFault::kNone;  ///< stall | throw | crash | kill | stop (the last three: udpm only)
  std::int64_t process_at_step = 0;  ///< [0, steps)
  double process_stop_s = 0.0; ///< "stop": continue after this many seconds, 0 = never, [0, 3600]
  bool any_network() const { return drop > 0 || duplicate > 0 || delay > 0 || reorder > 0; }
  bool operator==(const FaultConfig&) const = default;
};

/// Seeded random faults on every message a participant receives.
struct NetworkFaults {
  double drop = 0.0;        ///< fraction of messages lost, [0, 0.5]
  double duplicate = 0.0;   ///< fraction delivered twice (the copy up to delay_ms later), [0, 0.5]
  double delay = 0.0;       ///< fraction held back by a random time in (0, delay_ms], [0, 0.5]
  double reorder = 0.0;     ///< fraction held back until the next message has been delivered, [0, 0.5]
  double delay_ms = 20.0;   ///< longest delay [ms], (0, 10000]
  std::uint64_t seed = 1;   ///< each participant draws from its own stream of this seed
  bool any() const { return drop > 0 || duplicate > 0 || delay > 0 || reorder > 0; }
};

/// true for the faults that end or freeze the whole process (crash, kill, stop): with the memq
/// transport every participant shares it, so these need udpm.
constexpr bool EndsProcess(ProcessFault f) {
  return f == ProcessFault::kCrash || f == ProcessFault::kKill || f == ProcessFault::kStop;
}

/// One deterministic fault at one receiver (tests): the first message on `channel` whose step
/// is k (per-step and repair channels) or whose phase is `phase` (handshake) is acted upon.
struct TargetedFault {
  enum class Action { kDrop, kDuplicate, kDelay, kReorder };
  Action action = Action::kDrop;
  std::string channel;
  std::int64_t k = -1;
  std::int8_t phase = 0;
};

/// Every fault one participant is subject to.
struct Faults {
  NetworkFaults network;
  ProcessFault process = ProcessFault::kNone;
  std::int64_t at_step = -1;  ///< step of the process fault
  double stop_s = 0.0;        ///< kStop: continue after this many seconds (0: stay stopped)
  std::vector<TargetedFault> targeted;  ///< tests only
  double command_gain = 1.0;  ///< tests only (controller): multiply u_k (-1: a sign error)
};

/// Counts of injected faults (reported in summary.json).
struct InjectedFaults {
  std::int64_t dropped = 0, duplicated = 0, delayed = 0, reordered = 0;
};

/// Decides the fate of each received message and holds the delayed ones. Allocation-free once
/// its held slots have grown to the size of the messages they hold.
class FaultInjector {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Fate { kDeliver, kDrop, kDuplicate, kDelay, kReorder };

  FaultInjector() = default;
  /// `stream` separates participants: each draws its own sequence from the seed.
  FaultInjector(const Faults& faults, std::uint64_t stream);

  bool active() const { return active_; }
  /// The fate of one received message on `channel` (its encoded bytes, for targeted faults).
  Fate Decide(std::string_view channel, const std::uint8_t* data, std::size_t size,
              InjectedFaults* counts);
  /// Holds a copy of a message for `route` until `due` (or, if `after_next`, until the next
  /// message has been delivered). false if every slot is taken (then deliver it now).
  bool Hold(void* route, const std::uint8_t* data, std::size_t size, std::int64_t recv_utime,
            Clock::time_point due, bool after_next);
  /// A random due time for a delayed message or a duplicate's copy.
  Clock::time_point DelayedDue(Clock::time_point now);
  /// Calls `deliver(route, data, size, utime)` for every held message that is due (or waiting
  /// for the next message, when `a_message_was_delivered`), and frees its slot.
  template <class F>
  void Release(Clock::time_point now, bool a_message_was_delivered, F&& deliver) {
    for (Held& h : held_) {
      if (!h.used || !(h.due <= now || (h.after_next && a_message_was_delivered))) continue;
      h.used = false;  // free first: delivering may hold another message
      deliver(h.route, h.data.data(), h.data.size(), h.recv_utime);
    }
  }
  bool holding() const;
  /// When the earliest held message is due (Clock::time_point::max() if none).
  Clock::time_point NextDue() const;

 private:
  struct Held {
    bool used = false;
    bool after_next = false;
    void* route = nullptr;
    std::vector<std::uint8_t> data;
    std::int64_t recv_utime = 0;
    Clock::time_point due{};
  };
  double Uniform();

  bool active_ = false;
  NetworkFaults network_;
  std::vector<TargetedFault> targeted_;
  std::vector<bool> targeted_fired_;
  std::uint64_t state_ = 0;
  std::array<Held, 64> held_{};
};

}  // namespace rths::lockstep
