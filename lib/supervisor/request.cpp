// RunRequest::IsValid: which transport, URL, --external and --watch go together (supervisor/request.h).
#include "supervisor/request.h"

#include <fmt/format.h>

#include "lockstep/transport.h"

namespace rths::supervisor {

namespace {

/// The first rule `r` breaks, as a message naming the flags; "" if none.
std::string FirstBrokenRule(const RunRequest& r) {
  const std::string& t = r.transport;
  if (t != "udpm" && t != "memq" && t != "mixed")
    return fmt::format("--transport {}: unknown transport; allowed: udpm, memq, mixed", t);
  const bool external = !r.external.roles.empty();
  if (external && t == "memq") {
    return "--external needs the mixed (default) or udpm transport (an external process cannot join memq, which "
           "lives inside one process)";
  }
  if (!external && t == "mixed") return "--transport mixed needs --external ROLE (the participants to bridge to on udpm)";
  if (!r.lcm_url.empty() && t == "memq") return "--lcm-url needs the udpm or mixed transport";
  if (!r.lcm_url.empty() && r.lcm_url.rfind("udpm://", 0) != 0)
    return fmt::format("--lcm-url {}: must be a udpm:// URL (e.g. udpm://239.255.76.67:7667?ttl=0)", r.lcm_url);
  if (r.port_per_channel && t != "udpm") {
    return !external ? "--port-per-channel needs the udpm transport"
                     : "--port-per-channel needs --transport udpm (a mixed run, the default with --external, bridges "
                       "on one port)";
  }
  if (!r.lcm_url.empty()) {
    std::string why;
    if (!lockstep::UdpmUrl::Parse(r.lcm_url, &why)) return "--lcm-url " + why;
  }
  if (t == "mixed" && lockstep::IsPortPerChannel(r.lcm_url)) {
    return "--port-per-channel: a mixed run bridges its external participants on one udpm port: use --transport "
           "udpm for a port per channel";
  }
  if (r.live_sink != nullptr && t == "udpm")
    return "--watch: a udpm run's monitor listens to the run's URL; a live sink in this process needs memq or mixed";
  if (r.replay && t == "udpm") return "a replay runs on memq, or mixed with --external (docs/replay.md)";
  return "";
}

}  // namespace

bool RunRequest::IsValid(std::string* why) const {
  const std::string broken = FirstBrokenRule(*this);
  if (why) *why = broken;
  return broken.empty();
}

}  // namespace rths::supervisor
