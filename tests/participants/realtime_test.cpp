// Real-time paced mode (docs/realtime.md): the latency histogram, pacing to the wall clock with
// payloads unchanged, the miss policy, the scenario's [realtime] table, and what the supervisor
// reports (summary.json "realtime", the terminal). No timing thresholds: pacing is checked by
// what absolute deadlines guarantee (a paced run cannot finish before its simulated duration).
#include <doctest/doctest.h>

#include <thread>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "lockstep/realtime.h"
#include "participants/group.h"
#include "scenario/scenario.h"
#include "udpm_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths::lockstep::LatencyHistogram;
using namespace rths_test;

namespace {

const char* kPaced = R"(
[run]
name = "realtime_test"
duration_s = 0.25
[realtime]
enabled = true
)";

nlohmann::json ReadJson(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST_CASE("latency histogram: quantiles never below the truth and at most one bin (2.3 %) above") {
  LatencyHistogram h;
  CHECK(h.Quantile(0.5) == 0.0);
  for (int i = 1; i <= 1000; ++i) h.Add(i * 1e-6);  // 1 .. 1000 us
  CHECK(h.count() == 1000);
  CHECK(h.max_s() == doctest::Approx(1e-3));
  for (auto [q, truth] : {std::pair{0.5, 500e-6}, {0.99, 990e-6}, {0.999, 999e-6}, {1.0, 1000e-6}}) {
    CAPTURE(q);
    const double got = h.Quantile(q);
    CHECK(got >= truth * (1 - 1e-12));
    CHECK(got <= truth * std::pow(10.0, 1.0 / LatencyHistogram::kPerDecade) * (1 + 1e-12));
  }
  // Every value lands in a bin whose edges hold it; under- and overflow have their own bins.
  for (double v : {0.0, 5e-7, 1e-6, 1.2345e-4, 0.5, 99.0, 250.0}) {
    LatencyHistogram one;
    one.Add(v);
    int bin = -1;
    for (int i = 0; i < LatencyHistogram::kBins; ++i) {
      if (one.bin(i) == 1) bin = i;
    }
    CAPTURE(v);
    REQUIRE(bin >= 0);
    CHECK(LatencyHistogram::LowerEdge(bin) <= v);
    CHECK(v < LatencyHistogram::UpperEdge(bin));
  }
}

TEST_CASE("paced memq run: released on the wall clock, payloads identical to an unpaced run") {
  const auto dir = TempDir("paced");
  auto paced = rths::scenario::LoadScenario(WriteScenario(dir, kPaced).string());
  auto free_running = paced;
  free_running.realtime.enabled = false;
  const std::int64_t n = paced.steps();
  REQUIRE(n == 500);

  fs::create_directories(dir / "paced");
  fs::create_directories(dir / "free");
  const auto outcomes = rths::participants::RunGroupInProcess({paced}, 7, (dir / "paced").string());
  const auto free_outcomes = rths::participants::RunGroupInProcess({free_running}, 8, (dir / "free").string());
  const rths::participants::Outcome* clock = nullptr;
  for (const auto& o : outcomes) {
    CHECK(o.exit_code == 0);
    if (o.role == "integrator") clock = &o;
  }
  REQUIRE(clock != nullptr);
  // Step k is released at GO + k dt: the last step cannot start before (n-1) dt of wall time.
  CHECK(clock->stepping_s >= (n - 1) * paced.run.dt_s);
  const auto& rt = clock->realtime;
  CHECK(rt.paced);
  CHECK(rt.steps == n);
  CHECK(rt.latency.count() == n);
  std::int64_t binned = 0;
  for (int i = 0; i < LatencyHistogram::kBins; ++i) binned += rt.latency.bin(i);
  CHECK(binned == n);
  // The misses against the latencies: step k is issued at its release t_k or up to
  // max_release_late_s after it, and misses when it completes after t_{k+1} = t_k + dt. So a step
  // whose latency exceeds dt missed, and a step that missed took longer than dt - max_release_late_s
  // (1 us of slack for the clock's nanosecond rounding; a bin across a bound counts on its loose side).
  const double dt = paced.run.dt_s;
  std::int64_t surely_missed = 0, could_miss = 0;
  for (int i = 0; i < LatencyHistogram::kBins; ++i) {
    if (LatencyHistogram::LowerEdge(i) > dt + 1e-6) surely_missed += rt.latency.bin(i);
    if (LatencyHistogram::UpperEdge(i) > dt - rt.max_release_late_s - 1e-6) could_miss += rt.latency.bin(i);
  }
  CAPTURE(rt.max_release_late_s);
  CHECK(surely_missed <= rt.misses);
  CHECK(rt.misses <= could_miss);
  if (rt.misses == 0) {
    CHECK(rt.first_miss_step == -1);
    CHECK(rt.max_consecutive_misses == 0);
  } else {
    CHECK(rt.first_miss_step >= 0);
    CHECK(rt.first_miss_step < n);
    CHECK(rt.max_consecutive_misses >= 1);
    CHECK(rt.max_consecutive_misses <= rt.misses);
    CHECK(rt.misses <= n - rt.first_miss_step);  // none before the first
  }
  // The unpaced clock measures latencies too, but has no deadlines.
  for (const auto& o : free_outcomes) {
    if (o.role == "integrator") {
      CHECK_FALSE(o.realtime.paced);
      CHECK(o.realtime.misses == 0);
      CHECK(o.realtime.steps == n);
    }
  }
  const auto a = rths::io::ReadRunLog((dir / "paced" / "log.lcm").string());
  const auto b = rths::io::ReadRunLog((dir / "free" / "log.lcm").string());
  CHECK(a.CompleteSteps() == n);
  CHECK(rths::io::PayloadDigest(a) == rths::io::PayloadDigest(b));
}

TEST_CASE("miss policy: N consecutive misses stop the run with exit 8, the log valid up to the last step") {
  // A 10 us period (the shortest run.dt_s takes): nearly every step misses its deadline. A fast host
  // may keep the first few, so the stop is judged against the step the third consecutive miss fell on.
  const auto dir = TempDir("misses");
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
name = "misses"
dt_s = 1e-5
duration_s = 0.01
[realtime]
enabled = true
max_consecutive_misses = 3
)").string());
  const auto outcomes = rths::participants::RunGroupInProcess({s}, 9, dir.string());
  const auto v = rths::participants::Judge(outcomes);
  CHECK(v.failed);
  CHECK(v.exit_code == rths::kExitRealtime);
  CHECK(v.role == "integrator");
  CHECK(v.step >= 2);  // steps v.step - 2 .. v.step missed
  CHECK(v.step < s.steps() - 1);
  CHECK(v.what.find("3 consecutive deadline misses") != std::string::npos);
  for (const auto& o : outcomes) {
    if (o.role != "integrator") continue;
    CHECK(o.realtime.max_consecutive_misses == 3);
    CHECK(o.realtime.misses >= 3);
    CHECK(o.realtime.misses <= v.step + 1);
  }
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  CHECK_FALSE(log.done);
  CHECK(log.CompleteSteps() == v.step + 1);
}

TEST_CASE("[realtime] is validated like every table, naming file, key and range") {
  const auto dir = TempDir("validate");
  for (auto [text, key] : {std::pair{"[realtime]\npriority = 0\n", "realtime.priority"},
                           {"[realtime]\npriority = 100\n", "realtime.priority"},
                           {"[realtime]\nmax_consecutive_misses = -1\n", "realtime.max_consecutive_misses"},
                           {"[realtime]\nenabled = 1\n", "realtime.enabled"},
                           {"[realtime]\ndeadline_ms = 1\n", "deadline_ms"},
                           {"[realtime]\nspin_us = -1\n", "realtime.spin_us"},
                           {"[realtime]\nspin_us = 6000\n", "realtime.spin_us"},
                           {"[realtime]\ncpu = -2\n", "realtime.cpu"}}) {
    CAPTURE(text);
    const fs::path p = WriteScenario(dir, text);
    try {
      rths::scenario::LoadScenario(p.string());
      FAIL("accepted");
    } catch (const std::exception& e) {
      const std::string what = e.what();
      CHECK(what.find(p.string()) != std::string::npos);
      CHECK(what.find(key) != std::string::npos);
    }
  }
  // The defaults round-trip through ToToml.
  const auto s = rths::scenario::ParseScenario("[realtime]\nenabled = true\nmax_consecutive_misses = 7\npriority = 42\n"
                                               "sched_fifo = false\nlock_memory = false\nspin_us = 150\ncpu = 1\n",
                                               "x.toml");
  const auto t = rths::scenario::ParseScenario(rths::scenario::ToToml(s), "y.toml");
  CHECK(t.realtime.enabled);
  CHECK(t.realtime.max_consecutive_misses == 7);
  CHECK(t.realtime.priority == 42);
  CHECK_FALSE(t.realtime.sched_fifo);
  CHECK_FALSE(t.realtime.lock_memory);
  CHECK(t.realtime.spin_us == 150);
  CHECK(t.realtime.cpu == 1);
}

TEST_CASE("[realtime] spin_us: a paced run that busy-waits before each release gives the same payloads; cpu pins") {
  const auto dir = TempDir("spin");
  auto paced = rths::scenario::LoadScenario(WriteScenario(dir, kPaced).string());
  paced.realtime.spin_us = 300;  // of a 500 us period
  auto free_running = paced;
  free_running.realtime.enabled = false;
  const std::int64_t n = paced.steps();
  fs::create_directories(dir / "spin");
  fs::create_directories(dir / "free");
  const auto outcomes = rths::participants::RunGroupInProcess({paced}, 7, (dir / "spin").string());
  rths::participants::RunGroupInProcess({free_running}, 8, (dir / "free").string());
  for (const auto& o : outcomes) {
    CHECK(o.exit_code == 0);
    // Spinning ends at the release, never before: the last step cannot start before (n-1) dt.
    if (o.role == "integrator") CHECK(o.stepping_s >= (n - 1) * paced.run.dt_s);
  }
  CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((dir / "spin" / "log.lcm").string())) ==
        rths::io::PayloadDigest(rths::io::ReadRunLog((dir / "free" / "log.lcm").string())));
  // Pinning, on a thread of its own (affinity is per thread): CPU 0 exists; CPU 1023 does not here.
  rths::lockstep::RealtimeSetup pinned, impossible;
  std::thread([&] {
    pinned = rths::lockstep::EnterRealtime(false, 1, false, 0);
    impossible = rths::lockstep::EnterRealtime(false, 1, false, 1023);
  }).join();
  CHECK(pinned.cpu == 0);
  CHECK(pinned.note.empty());
  CHECK(impossible.cpu == -1);
  CHECK(impossible.note.find("cannot pin to CPU 1023") != std::string::npos);
}

TEST_CASE("rths run --realtime (udpm): summary and terminal report latency, misses and the set-up") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("cli");
  const fs::path scenario = WriteScenario(dir, "[run]\nname = \"cli\"\nduration_s = 0.25\n");
  std::string out;
  REQUIRE(RunCli("--realtime --transport udpm --out " + (dir / "run").string() + " " + scenario.string(), &out) == 0);
  CHECK(out.find("transport udpm") != std::string::npos);
  CHECK(out.find("paced at 2000 Hz") != std::string::npos);
  CHECK(out.find("step latency       p50") != std::string::npos);
  CHECK(out.find("deadline misses") != std::string::npos);
  const auto j = ReadJson(dir / "run" / "summary.json");
  REQUIRE(j.contains("realtime"));
  const auto& rt = j["realtime"];
  CHECK(rt["steps"] == 500);
  CHECK(rt["processes"] == 5);
  CHECK(rt["latency_p50_us"].get<double>() <= rt["latency_p99_us"].get<double>());
  CHECK(rt["latency_p99_us"].get<double>() <= rt["latency_p999_us"].get<double>());
  CHECK(rt["latency_p999_us"].get<double>() <= rt["latency_max_us"].get<double>());
  std::int64_t binned = 0;
  for (const auto& b : rt["latency_histogram_us"]) binned += b[2].get<std::int64_t>();
  CHECK(binned == 500);
  CHECK(j["stepping_s"].get<double>() >= 499 * 0.0005);
  // Without the privileges, it says so plainly (and still runs, paced).
  std::string out2;
  REQUIRE(RunCli("--realtime --transport memq --out " + (dir / "unpriv").string() + " " + scenario.string(), &out2,
                 "setpriv --bounding-set=-sys_nice,-ipc_lock --inh-caps=-sys_nice,-ipc_lock ") == 0);
  CHECK(out2.find("NOT real-time") != std::string::npos);
  CHECK(out2.find("SCHED_FIFO priority 80 not permitted") != std::string::npos);
  const auto j2 = ReadJson(dir / "unpriv" / "summary.json");
  CHECK(j2["realtime"]["sched_fifo_processes"] == 0);
  // The miss policy through the CLI: exit 8, named.
  const fs::path fast = dir / "fast.toml";
  std::ofstream(fast) << "[run]\nname = \"fast\"\ndt_s = 1e-5\nduration_s = 0.01\n[realtime]\nmax_consecutive_misses = 2\n";
  std::string out3;
  CHECK(RunCli("--realtime --out " + (dir / "fast").string() + " " + fast.string(), &out3) == 8);
  CHECK(out3.find("STOPPED by the real-time miss policy") != std::string::npos);
  CHECK(ReadJson(dir / "fast" / "summary.json")["status"] == "stopped by the miss policy");
}
