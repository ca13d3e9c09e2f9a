#pragma once
/// @file Received messages of one per-step channel, kept by step index k (docs/lockstep.md,
/// "First copy wins").
#include <array>
#include <cstdint>
#include <utility>

#include <lcm/lcm-cpp.hpp>

namespace rths::lockstep {

/// What a mailbox did with a message.
enum class Put { kNew, kDuplicate, kStale, kForeign, kBad };

/// Received messages of one channel, kept by step index k in a small ring, decoded into
/// preallocated slots. The first copy of (channel, k) is "new"; later copies are duplicates.
template <class Msg, int kDepth = 4>
class StepMailbox {
 public:
  StepMailbox() { ks_.fill(-1); }

  /// Decodes `rbuf`; keeps it if it is the first copy of its k for this run.
  Put Add(const lcm::ReceiveBuffer* rbuf, std::int64_t run_id) {
    if (scratch_.decode(rbuf->data, 0, rbuf->data_size) < 0) return Put::kBad;
    if (scratch_.run_id != run_id) return Put::kForeign;
    const std::int64_t k = scratch_.k;
    if (k < 0) return Put::kBad;
    last_k_ = k;
    const int slot = static_cast<int>(k % kDepth);
    if (ks_[slot] == k) return Put::kDuplicate;
    if (ks_[slot] > k) return Put::kStale;
    std::swap(slots_[slot], scratch_);
    ks_[slot] = k;
    return Put::kNew;
  }
  /// The message of step k, or nullptr if it has not arrived (or has left the ring).
  const Msg* Get(std::int64_t k) const {
    if (k < 0) return nullptr;
    const int slot = static_cast<int>(k % kDepth);
    return ks_[slot] == k ? &slots_[slot] : nullptr;
  }
  /// k of the message just added (valid after Add returned kNew, kDuplicate or kStale).
  std::int64_t last_k() const { return last_k_; }

 private:
  std::array<Msg, kDepth> slots_{};
  std::array<std::int64_t, kDepth> ks_{};
  Msg scratch_{};
  std::int64_t last_k_ = -1;
};

}  // namespace rths::lockstep
