#include "lockstep/follow_ledger.h"

namespace rths::lockstep {

FollowCounts FollowLedger::Counts() const {
  FollowCounts c;
  for (const FollowStep s : steps_) {
    switch (s) {
      case FollowStep::kExact: ++c.exact; break;
      case FollowStep::kResumed: ++c.resumed; break;
      case FollowStep::kHeld: ++c.held; break;
      case FollowStep::kUnseen: ++c.unseen; break;
    }
  }
  return c;
}

std::vector<StepRange> FollowLedger::Ranges(FollowStep c) const {
  std::vector<StepRange> out;
  const auto n = static_cast<std::int64_t>(steps_.size());
  for (std::int64_t k = 0; k < n; ++k) {
    if (steps_[static_cast<std::size_t>(k)] != c) continue;
    if (!out.empty() && out.back().second == k - 1) {
      out.back().second = k;
    } else {
      out.emplace_back(k, k);
    }
  }
  return out;
}

}  // namespace rths::lockstep
