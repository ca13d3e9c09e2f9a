// RunRequest::IsValid (supervisor/request.h): the one place of the rules for which transport,
// --lcm-url, --external, --port-per-channel, --watch's live sink and a replay go together; each
// broken rule names the flags. And the default transport (supervisor/run_text.h).
#include <doctest/doctest.h>

#include <string>

#include "io/run_log.h"
#include "lockstep/live_feed.h"
#include "supervisor/request.h"
#include "supervisor/run_text.h"

namespace sup = rths::supervisor;

namespace {

/// The message of the first broken rule ("" if valid), checking IsValid's answer agrees.
std::string Why(const sup::RunRequest& r) {
  std::string why = "unset";
  const bool valid = r.IsValid(&why);
  CHECK(valid == why.empty());
  CHECK(r.IsValid() == valid);
  return why;
}

sup::RunRequest On(const std::string& transport) {
  sup::RunRequest r;
  r.transport = transport;
  return r;
}

}  // namespace

TEST_CASE("RunRequest::IsValid: the valid combinations") {
  CHECK(Why(On("udpm")) == "");
  CHECK(Why(On("memq")) == "");
  auto r = On("udpm");
  r.lcm_url = "udpm://239.255.76.67:7667?ttl=1";
  r.port_per_channel = true;
  r.external.roles = {"plant"};
  CHECK(Why(r) == "");
  r = On("mixed");
  r.external.roles = {"controller"};
  r.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  CHECK(Why(r) == "");
}

TEST_CASE("RunRequest::IsValid: each invalid combination names the flags") {
  CHECK(Why(On("tcp")).find("--transport tcp") == 0);

  auto r = On("memq");
  r.external.roles = {"plant"};
  CHECK(Why(r).find("--external needs the mixed (default) or udpm transport") == 0);

  CHECK(Why(On("mixed")).find("--transport mixed needs --external ROLE") == 0);

  r = On("memq");
  r.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  CHECK(Why(r) == "--lcm-url needs the udpm or mixed transport");

  r = On("udpm");
  r.lcm_url = "memq://";
  CHECK(Why(r).find("--lcm-url memq://: must be a udpm:// URL") == 0);

  r = On("udpm");
  r.lcm_url = "udpm://239.255.76.67:notaport";
  CHECK(Why(r).find("--lcm-url ") == 0);

  r = On("memq");
  r.port_per_channel = true;
  CHECK(Why(r) == "--port-per-channel needs the udpm transport");
  r = On("mixed");
  r.external.roles = {"plant"};
  r.port_per_channel = true;
  CHECK(Why(r).find("--port-per-channel needs --transport udpm (a mixed run") == 0);
  r.port_per_channel = false;
  r.lcm_url = "udpm://239.255.76.67:7667?ttl=0&port_per_channel=1";
  CHECK(Why(r).find("--port-per-channel: a mixed run bridges") == 0);

  struct NullSink : rths::lockstep::LiveSink {
    void Push(const rths::monitor_t&) override {}
  } sink;
  r = On("udpm");
  r.live_sink = &sink;
  CHECK(Why(r).find("--watch: ") == 0);
  r.transport = "memq";
  CHECK(Why(r) == "");

  rths::io::RunLog record;
  r = On("udpm");
  r.replay = sup::ReplaySource{&record, 1, {"plant"}};
  CHECK(Why(r).find("a replay runs on memq") == 0);
  r.transport = "memq";
  CHECK(Why(r) == "");
}

TEST_CASE("DefaultTransport: mixed with --external, memq for a paced run without udpm options, else udpm") {
  CHECK(sup::DefaultTransport(true, true, "", false) == "mixed");
  CHECK(sup::DefaultTransport(false, true, "", false) == "memq");
  CHECK(sup::DefaultTransport(false, true, "udpm://239.255.76.67:7667", false) == "udpm");
  CHECK(sup::DefaultTransport(false, true, "", true) == "udpm");
  CHECK(sup::DefaultTransport(false, false, "", false) == "udpm");
}
