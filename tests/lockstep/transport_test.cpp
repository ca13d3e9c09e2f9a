// The per-channel udpm transport (lockstep/transport.h): URL form, LCM wire compatibility, port
// isolation, and a whole run bit-identical to one port and to memq; the in-process queue of memq
// runs (InprocChannels): order, re-entrant publishing, no allocation.
#include <doctest/doctest.h>

#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "alloc_counter.h"
#include "io/run_log.h"
#include "lockstep/transport.h"
#include "run_support.h"
#include "udpm_support.h"
#include "test_support.h"

using namespace rths_test;
namespace ls = rths::lockstep;

namespace {

/// A base port of this test process's own (P .. P+6), apart from other test processes' ports.
int TestPort(int slot) { return 20000 + (::getpid() % 1500) * 24 + slot * 8; }

/// Handles what `ch` receives for up to `ms`, until `*got` reaches `want`.
void Pump(ls::UdpmChannels* ch, const int* got, int want, int ms = 500) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
  while (*got < want && std::chrono::steady_clock::now() < end) ch->HandleTimeout(10);
}

struct Received {
  int n = 0;
  std::string last;
  static void On(void* self, const lcm::ReceiveBuffer* rb) {
    auto* r = static_cast<Received*>(self);
    ++r->n;
    r->last.assign(static_cast<const char*>(rb->data), rb->data_size);
  }
};

}  // namespace

TEST_CASE("UdpmUrl: parse, channel URLs, errors") {
  std::string why;
  const auto u = ls::UdpmUrl::Parse("udpm://239.255.76.67:7667?ttl=0&port_per_channel=1&recv_buf_size=4096", &why);
  REQUIRE(u);
  CHECK(u->group == "239.255.76.67");
  CHECK(u->port == 7667);
  CHECK(u->ttl == 0);
  CHECK(u->recv_buf_size == 4096);
  CHECK(u->port_per_channel);
  CHECK(ls::IsPortPerChannel(u->ToString()));
  CHECK(ls::UdpmUrl::Parse(u->ToString())->port == 7667);
  // Each channel on base + its index; the plain LCM URL carries no port_per_channel.
  CHECK(u->ChannelUrl(ls::kChHandshake) == "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4096");
  CHECK(u->ChannelUrl(ls::kChDesired) == "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4096");
  CHECK(u->ChannelUrl(ls::kChRepair) == "udpm://239.255.76.67:7673?ttl=0&recv_buf_size=4096");
  CHECK(ls::PortOffset(ls::kChAck) == 5);
  CHECK(ls::PortOffset("OTHER") == -1);
  const auto single = ls::UdpmUrl::Parse("udpm://239.255.76.67:7667?ttl=1");
  REQUIRE(single);
  CHECK_FALSE(single->port_per_channel);
  CHECK(single->ChannelUrl(ls::kChAck) == "udpm://239.255.76.67:7667?ttl=1");
  CHECK_FALSE(ls::IsPortPerChannel("udpm://239.255.76.67:7667?ttl=0"));
  CHECK_FALSE(ls::IsPortPerChannel("memq://"));
  CHECK_FALSE(ls::UdpmUrl::Parse("memq://", &why));
  CHECK(why.find("not a udpm:// URL") != std::string::npos);
  CHECK_FALSE(ls::UdpmUrl::Parse("udpm://239.255.76.67:65530?port_per_channel=1", &why));
  CHECK(why.find("PORT+6") != std::string::npos);
  CHECK_FALSE(ls::UdpmUrl::Parse("udpm://239.255.76.67:76x7", &why));
  CHECK_FALSE(ls::UdpmUrl::Parse("udpm://239.255.76.67:7667?ttl=300", &why));
  CHECK_FALSE(ls::UdpmUrl::Parse("udpm://239.255.76.67:7667?port_per_channel=yes", &why));
}

TEST_CASE("UdpmChannels: only subscribed channels arrive; LCM reads and writes the same datagrams; ports isolate") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << ls::CheckMulticastRoute());
  const auto url = *ls::UdpmUrl::Parse(fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1", TestPort(0)));
  ls::UdpmChannels a(url), b(url);
  REQUIRE(a.good());
  Received desired, command;
  REQUIRE(b.Subscribe(ls::kChDesired, &Received::On, &desired));
  CHECK_FALSE(b.Subscribe("NOT_A_RUN_CHANNEL", &Received::On, &desired));

  // A channel nobody here reads reaches no socket of b.
  const std::string payload = "payload\0with a NUL";
  REQUIRE(a.Publish(ls::kChCommand, payload.data(), payload.size()) == 0);
  REQUIRE(a.Publish(ls::kChDesired, payload.data(), payload.size()) == 0);
  Pump(&b, &desired.n, 1);
  CHECK(desired.n == 1);
  CHECK(desired.last == payload);
  CHECK(b.received() == 1);  // the command_t never came in
  CHECK(a.Publish("NOT_A_RUN_CHANNEL", payload.data(), payload.size()) == -1);

  // LCM on the channel's own URL (what lcm-spy uses) hears our datagrams, and we hear LCM's.
  lcm::LCM spy(url.ChannelUrl(ls::kChCommand));
  REQUIRE(spy.good());
  struct Spy {
    int n = 0;
    std::string channel, data;
    void On(const lcm::ReceiveBuffer* rb, const std::string& ch) {
      ++n;
      channel = ch;
      data.assign(static_cast<const char*>(rb->data), rb->data_size);
    }
  } seen;
  spy.subscribe(".*", &Spy::On, &seen);
  REQUIRE(a.Publish(ls::kChCommand, payload.data(), payload.size()) == 0);
  for (int i = 0; i < 50 && seen.n == 0; ++i) spy.handleTimeout(10);
  CHECK(seen.n == 1);
  CHECK(seen.channel == ls::kChCommand);
  CHECK(seen.data == payload);

  REQUIRE(b.Subscribe(ls::kChCommand, &Received::On, &command));
  lcm::LCM writer(url.ChannelUrl(ls::kChCommand));
  const std::string from_lcm = "from lcm";
  writer.publish(ls::kChCommand, from_lcm.data(), from_lcm.size());
  Pump(&b, &command.n, 1);
  CHECK(command.n == 1);
  CHECK(command.last == from_lcm);

  // Another run's base port: nothing crosses.
  const auto other_url =
      *ls::UdpmUrl::Parse(fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1", TestPort(1)));
  ls::UdpmChannels other(other_url);
  Received foreign;
  REQUIRE(other.Subscribe(ls::kChDesired, &Received::On, &foreign));
  REQUIRE(a.Publish(ls::kChDesired, payload.data(), payload.size()) == 0);
  Pump(&b, &desired.n, 2);
  CHECK(desired.n == 2);
  for (int i = 0; i < 10; ++i) other.HandleTimeout(10);
  CHECK(foreign.n == 0);
}

TEST_CASE("a run with a port per channel is bit-identical to one port and to memq") {
  const fs::path scenario = fs::path(RTHS_SOURCE_DIR) / "tests/data/regression_short.toml";
  const auto s = rths::scenario::LoadScenario(scenario.string());
  const auto memq = TempDir("memq");
  REQUIRE(RunMemq({s}, memq).code == 0);
  const std::string digest = rths::io::PayloadDigest(rths::io::ReadRunLog((memq / "log.lcm").string()));
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << ls::CheckMulticastRoute());

  const auto one = TempDir("one_port");
  fs::remove_all(one);
  std::string output;
  REQUIRE(RunCli(scenario.string() + " --transport udpm --out " + one.string(), &output) == 0);
  CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((one / "log.lcm").string())) == digest);

  const auto per = TempDir("per_channel");
  fs::remove_all(per);
  REQUIRE(RunCli(scenario.string() + " --transport udpm --port-per-channel --out " + per.string(), &output) == 0);
  CAPTURE(output);
  const auto log = rths::io::ReadRunLog((per / "log.lcm").string());
  CHECK(log.CompleteSteps() == s.steps());
  CHECK(rths::io::PayloadDigest(log) == digest);
  const auto summary = nlohmann::json::parse(std::ifstream(per / "summary.json"));
  CHECK(summary["stopped"] == "no");
  CHECK(ls::IsPortPerChannel(summary["lcm_url"].get<std::string>()));

  // The same through an explicit URL, on this test's own ports.
  const auto url_dir = TempDir("per_channel_url");
  fs::remove_all(url_dir);
  const std::string url = fmt::format("'udpm://239.255.76.67:{}?ttl=0&port_per_channel=1'", TestPort(2));
  REQUIRE(RunCli(scenario.string() + " --lcm-url " + url + " --out " + url_dir.string(), &output) == 0);
  CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((url_dir / "log.lcm").string())) == digest);

  // A crashed participant is still noticed and the others stopped through the handshake port.
  const auto crash = TempDir("per_channel_crash");
  const auto crash_scen =
      WriteScenario(crash, "[run]\nname = \"transport_test\"\nduration_s = 0.5\n[lockstep]\nrerequest_ms = 20.0\n"
                           "stall_budget_s = 2.0\nhandshake_timeout_s = 5.0\n[faults.process]\nrole = \"plant\"\n"
                           "kind = \"crash\"\nat_step = 250\n");
  const int code =
      RunCli(crash_scen.string() + " --port-per-channel --out " + (crash / "run").string(), &output);
  CAPTURE(output);
  CHECK(code == 128 + SIGABRT);
  CHECK(output.find("FAILED: plant was killed by signal 6") != std::string::npos);
  CHECK(rths::io::ReadRunLog((crash / "run" / "log.lcm").string()).CompleteSteps() == 250);
}

TEST_CASE("rths run --port-per-channel needs udpm; a bad --lcm-url is a usage error") {
  std::string output;
  CHECK(RunCli("--transport memq --port-per-channel", &output) == 2);
  CHECK(output.find("--port-per-channel needs the udpm transport") != std::string::npos);
  CHECK(RunCli("--lcm-url 'udpm://239.255.76.67:65533?port_per_channel=1'", &output) == 2);
  CHECK(output.find("PORT+6") != std::string::npos);
}

TEST_CASE("a port per channel: 5 % of every fault on every channel and a small receive buffer, still bit-identical") {
  const std::string tiny = "[run]\nname = \"transport_faults\"\nduration_s = 0.25\n[lockstep]\nrerequest_ms = 10.0\n"
                           "stall_budget_s = 5.0\nhandshake_timeout_s = 5.0\n";
  const auto base = TempDir("faults_clean");
  const auto clean = rths::scenario::LoadScenario(WriteScenario(base, tiny).string());
  REQUIRE(RunMemq({clean}, base).code == 0);
  const std::string reference = rths::io::PayloadDigest(rths::io::ReadRunLog((base / "log.lcm").string()));
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << ls::CheckMulticastRoute());
  // Faults are injected on every receive path (as on one port); recv_buf_bytes shrinks every one
  // of the per-channel sockets (SO_RCVBUF, from the URL's recv_buf_size).
  for (const std::string faults : {"[faults]\ndrop = 0.05\nduplicate = 0.05\ndelay = 0.05\nreorder = 0.05\n"
                                   "delay_ms = 15.0\nseed = 11\n",
                                   "[faults]\nrecv_buf_bytes = 2048\n"}) {
    CAPTURE(faults);
    const auto dir = TempDir("faults_per_channel");
    const auto scen = WriteScenario(dir, tiny + faults);
    std::string output;
    const int code = RunCli(scen.string() + " --port-per-channel --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    REQUIRE(code == 0);
    CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((dir / "run" / "log.lcm").string())) == reference);
    const auto summary = nlohmann::json::parse(std::ifstream(dir / "run" / "summary.json"));
    if (faults.find("drop") != std::string::npos) CHECK(summary["link"]["repaired"].get<std::int64_t>() > 0);
    if (faults.find("recv_buf") != std::string::npos) {
      CHECK(summary["lcm_url"].get<std::string>().find("recv_buf_size=2048") != std::string::npos);
    }
  }
}

TEST_CASE("UdpmChannels: sending and receiving a message allocates nothing") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << ls::CheckMulticastRoute());
  const auto url = *ls::UdpmUrl::Parse(fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1", TestPort(3)));
  ls::UdpmChannels ch(url);
  struct Count {
    int n = 0;
    static void On(void* self, const lcm::ReceiveBuffer*) { ++static_cast<Count*>(self)->n; }
  } count;
  REQUIRE(ch.Subscribe(ls::kChMeasured, &Count::On, &count));
  const std::array<std::uint8_t, 200> payload{};
  REQUIRE(ch.Publish(ls::kChMeasured, payload.data(), payload.size()) == 0);
  Pump(&ch, &count.n, 1);
  REQUIRE(count.n == 1);
  const long before = rths_test::AllocationCount();
  for (int i = 0; i < 100; ++i) {
    ch.Publish(ls::kChMeasured, payload.data(), payload.size());
    ch.HandleTimeout(100);
  }
  const long allocations = rths_test::AllocationCount() - before;
  CHECK(count.n == 101);
  CHECK(allocations == 0);
}

TEST_CASE("InprocChannels (memq): publish order across channels, messages published by handlers, no allocation") {
  ls::InprocChannels bus;
  struct Log {
    ls::InprocChannels* bus;
    std::vector<std::string> seen;  // "CHANNEL:payload" in the order handed over
    static void Desired(void* self, const lcm::ReceiveBuffer* rb) {
      auto* log = static_cast<Log*>(self);
      const std::string p(static_cast<const char*>(rb->data), rb->data_size);
      log->seen.push_back("D:" + p);
      // A handler answers at once, as a participant does: its message queues behind the others.
      const std::string answer = "c" + p;
      log->bus->Publish(ls::kChCommand, answer.data(), static_cast<unsigned>(answer.size()));
    }
    static void Command(void* self, const lcm::ReceiveBuffer* rb) {
      static_cast<Log*>(self)->seen.push_back("C:" + std::string(static_cast<const char*>(rb->data), rb->data_size));
    }
    static void Measured(void* self, const lcm::ReceiveBuffer* rb) {
      static_cast<Log*>(self)->seen.push_back("M:" + std::string(static_cast<const char*>(rb->data), rb->data_size));
    }
  } log{&bus, {}};
  REQUIRE(bus.Subscribe(ls::kChDesired, &Log::Desired, &log));
  REQUIRE(bus.Subscribe(ls::kChCommand, &Log::Command, &log));
  REQUIRE(bus.Subscribe(ls::kChMeasured, &Log::Measured, &log));
  CHECK_FALSE(bus.Subscribe("SOME_OTHER_CHANNEL", &Log::Command, &log));
  CHECK(bus.error().find("SOME_OTHER_CHANNEL") != std::string::npos);
  CHECK(bus.Publish("SOME_OTHER_CHANNEL", "x", 1) == -1);

  // Nothing queued: it waits the timeout (a deadline of the caller's) and reports nothing.
  const auto t0 = std::chrono::steady_clock::now();
  CHECK(bus.HandleTimeout(20) == 0);
  CHECK(std::chrono::steady_clock::now() - t0 >= std::chrono::milliseconds(20));

  bus.Publish(ls::kChMeasured, "1", 1);
  bus.Publish(ls::kChDesired, "1", 1);
  bus.Publish(ls::kChMeasured, "2", 1);
  CHECK(bus.HandleTimeout(100) == 4);  // the three, then the command the desired_t handler sent
  CHECK(log.seen == std::vector<std::string>{"M:1", "D:1", "M:2", "C:c1"});
  CHECK(bus.HandleTimeout(0) == 0);

  // Past its first capacity the queue grows once, keeping the order; then nothing is allocated.
  log.seen.clear();
  for (int i = 0; i < 100; ++i) bus.Publish(ls::kChMeasured, &"0123456789"[i % 10], 1);
  int handled = 0;
  while (int n = bus.HandleTimeout(0)) handled += n;
  CHECK(handled == 100);
  REQUIRE(log.seen.size() == 100);
  for (int i = 0; i < 100; ++i) CHECK(log.seen[i] == std::string("M:") + "0123456789"[i % 10]);
  log.seen.clear();
  log.seen.reserve(400);
  const long before = rths_test::AllocationCount();
  for (int i = 0; i < 100; ++i) {
    bus.Publish(ls::kChMeasured, "m", 1);
    bus.Publish(ls::kChCommand, "c", 1);
    bus.HandleTimeout(0);
  }
  CHECK(rths_test::AllocationCount() - before == 0);
  CHECK(log.seen.size() == 200);
  CHECK(bus.sent() == 3 + 1 + 100 + 200);
}
