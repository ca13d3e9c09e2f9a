#pragma once
/// @file The messages a participant lacks, as listed in its repair_t (docs/lockstep.md, "Repair").
#include <array>
#include <cstdint>

#include "lockstep/protocol.h"

namespace rths::lockstep {

/// (channel, step) pairs, at most kCapacity.
class WantList {
 public:
  static constexpr int kCapacity = 8;
  void Add(Channel channel, std::int64_t k) {
    if (n_ < kCapacity && k >= 0) items_[n_++] = {channel, k};
  }
  int size() const { return n_; }
  bool empty() const { return n_ == 0; }
  Channel channel(int i) const { return items_[i].channel; }
  std::int64_t k(int i) const { return items_[i].k; }

 private:
  struct Item {
    Channel channel;
    std::int64_t k;
  };
  std::array<Item, kCapacity> items_{};
  int n_ = 0;
};

}  // namespace rths::lockstep
