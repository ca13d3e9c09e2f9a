#pragma once
// Whether this host can run udpm:// (a multicast route); links rths_lockstep.

#include "lockstep/transport.h"

#include "test_support.h"

namespace rths_test {

/// Whether udpm:// works here: a multicast route exists (docs/lockstep.md).
inline bool UdpmAvailable() { return rths::lockstep::CheckMulticastRoute().empty(); }

}  // namespace rths_test
