#include "lockstep/abort.h"

#include <lcm/lcm-cpp.hpp>

#include "lockstep/protocol.h"
#include "lockstep/transport.h"
#include "rths/handshake_t.hpp"

namespace rths::lockstep {

Bytes EncodeAbort(std::int64_t run_id, const std::string& sender, const std::string& reason, std::int64_t k) {
  rths::handshake_t h{};
  h.run_id = run_id;
  h.phase = kAbort;
  h.participant = sender;
  h.k = k;
  h.n_roster = 0;
  h.reason = reason;
  Bytes bytes;
  Encode(h, &bytes);
  return bytes;
}

bool BroadcastAbort(const std::string& url, std::int64_t run_id, const std::string& sender, const std::string& reason,
                    std::int64_t k) {
  const auto parsed = UdpmUrl::Parse(url);
  lcm::LCM lcm(parsed ? parsed->ChannelUrl(kChHandshake) : url);
  if (!lcm.good()) return false;
  const Bytes bytes = EncodeAbort(run_id, sender, reason, k);
  for (int i = 0; i < 3; ++i) lcm.publish(kChHandshake, bytes.data(), bytes.size());
  return true;
}

}  // namespace rths::lockstep
