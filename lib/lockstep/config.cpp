#include "lockstep/config.h"

#include <algorithm>

namespace rths::lockstep {

double LockstepConfig::RerequestAfterS(int n, double typical_step_s) const {
  const double longest = rerequest_ms * 1e-3;
  const double first =
      typical_step_s > 0 ? std::clamp(8.0 * typical_step_s, std::min(kMinRerequestS, longest), longest) : longest;
  const double cap = std::max(longest, 1.0);
  // The first few re-requests come at the same pace (a repair may need several round trips on
  // a lossy link); then each waits twice as long (a loaded host is not flooded).
  constexpr int kSteady = 4;
  double wait = first;
  for (int i = kSteady; i < n && wait < cap; ++i) wait *= 2.0;
  return std::min(wait, cap);
}

double LockstepConfig::LingerS() const {
  return std::min(stall_budget_s, std::max(0.5, 10.0 * rerequest_ms * 1e-3));
}

}  // namespace rths::lockstep
