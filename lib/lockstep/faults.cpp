#include "lockstep/faults.h"

#include <algorithm>

namespace rths::lockstep {

namespace {
/// splitmix64: a small, well-mixed generator; one stream per participant.
std::uint64_t SplitMix(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::int64_t BigEndian64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<std::int64_t>(v);
}
}  // namespace

FaultInjector::FaultInjector(const Faults& faults, std::uint64_t stream)
    : active_(faults.network.any() || !faults.targeted.empty()),
      network_(faults.network),
      targeted_(faults.targeted),
      targeted_fired_(faults.targeted.size(), false),
      state_(faults.network.seed * 0x2545F4914F6CDD1DULL + stream) {}

double FaultInjector::Uniform() { return static_cast<double>(SplitMix(&state_) >> 11) * 0x1.0p-53; }

FaultInjector::Fate FaultInjector::Decide(std::string_view channel, const std::uint8_t* data,
                                          std::size_t size, InjectedFaults* counts) {
  if (!active_) return Fate::kDeliver;
  Fate fate = Fate::kDeliver;
  for (std::size_t i = 0; i < targeted_.size(); ++i) {
    const TargetedFault& t = targeted_[i];
    if (targeted_fired_[i] || t.channel != channel) continue;
    // Handshake: run_id (8 bytes after the 8-byte hash) then the phase byte; others: run_id, k.
    const bool handshake = t.phase != 0;
    if (handshake ? (size < 17 || static_cast<std::int8_t>(data[16]) != t.phase)
                  : (size < 24 || BigEndian64(data + 16) != t.k)) {
      continue;
    }
    targeted_fired_[i] = true;
    switch (t.action) {
      case TargetedFault::Action::kDrop: fate = Fate::kDrop; break;
      case TargetedFault::Action::kDuplicate: fate = Fate::kDuplicate; break;
      case TargetedFault::Action::kDelay: fate = Fate::kDelay; break;
      case TargetedFault::Action::kReorder: fate = Fate::kReorder; break;
    }
    break;
  }
  if (fate == Fate::kDeliver && network_.any()) {
    double u = Uniform();
    if ((u -= network_.drop) < 0) {
      fate = Fate::kDrop;
    } else if ((u -= network_.duplicate) < 0) {
      fate = Fate::kDuplicate;
    } else if ((u -= network_.delay) < 0) {
      fate = Fate::kDelay;
    } else if ((u -= network_.reorder) < 0) {
      fate = Fate::kReorder;
    }
  }
  switch (fate) {
    case Fate::kDrop: ++counts->dropped; break;
    case Fate::kDuplicate: ++counts->duplicated; break;
    case Fate::kDelay: ++counts->delayed; break;
    case Fate::kReorder: ++counts->reordered; break;
    case Fate::kDeliver: break;
  }
  return fate;
}

FaultInjector::Clock::time_point FaultInjector::DelayedDue(Clock::time_point now) {
  const double ms = network_.delay_ms * (1.0 - Uniform());  // (0, delay_ms]
  return now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(ms));
}

bool FaultInjector::Hold(void* route, const std::uint8_t* data, std::size_t size, std::int64_t recv_utime,
                         Clock::time_point due, bool after_next) {
  for (Held& h : held_) {
    if (h.used) continue;
    h.used = true;
    h.after_next = after_next;
    h.route = route;
    h.data.assign(data, data + size);
    h.recv_utime = recv_utime;
    h.due = due;
    return true;
  }
  return false;
}

FaultInjector::Clock::time_point FaultInjector::NextDue() const {
  Clock::time_point t = Clock::time_point::max();
  for (const Held& h : held_) {
    if (h.used) t = std::min(t, h.due);
  }
  return t;
}

bool FaultInjector::holding() const {
  return std::any_of(held_.begin(), held_.end(), [](const Held& h) { return h.used; });
}

}  // namespace rths::lockstep
