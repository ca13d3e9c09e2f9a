#pragma once
/// @file A participant's encoded answers of the last few steps, so that a repeated request gets
/// the very same bytes (docs/lockstep.md, "Repair": re-sent, never recomputed).
#include <array>
#include <cstdint>

#include "lockstep/protocol.h"

namespace rths::lockstep {

class AnswerCache {
 public:
  static constexpr int kDepth = 4;
  AnswerCache() { ks_.fill(-1); }
  /// Slot to encode the answer of step k into (then call Commit(k)).
  Bytes* Slot(std::int64_t k) { return &bytes_[k % kDepth]; }
  void Commit(std::int64_t k) { ks_[k % kDepth] = k; }
  const Bytes* Get(std::int64_t k) const {
    return (k >= 0 && ks_[k % kDepth] == k) ? &bytes_[k % kDepth] : nullptr;
  }

 private:
  std::array<Bytes, kDepth> bytes_{};
  std::array<std::int64_t, kDepth> ks_{};
};

}  // namespace rths::lockstep
