#pragma once
/// @file What the link lost and what the protocol repaired, per participant (summary.json
/// `participants.<role>.link`; docs/lockstep.md "Repair").
#include <cstdint>

#include "lockstep/faults.h"

namespace rths::lockstep {

struct LinkStats {
  std::int64_t rerequests = 0;         ///< clock: re-requests it sent (repair_t of an incomplete step)
  std::int64_t steps_rerequested = 0;  ///< clock: steps that needed at least one re-request
  std::int64_t repair_requests = 0;    ///< repair_t it sent listing inputs it lacked
  std::int64_t resent = 0;             ///< messages it re-sent from its cache because one lacked them
  std::int64_t repaired = 0;           ///< messages it lacked, asked for, and then received
  std::int64_t duplicates = 0;         ///< copies of messages it already held (ignored)
  std::int64_t stale = 0;              ///< messages of steps it had left behind (ignored)
  std::int64_t foreign = 0;            ///< messages of another run on the same port (ignored)
  InjectedFaults injected;             ///< faults injected on its receive path ([faults])
};

}  // namespace rths::lockstep
