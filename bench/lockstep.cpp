// bench-lockstep: LCM ping-pong round trips/s, lockstep steps/s on udpm and memq, and the
// lockstep rate as a fraction of the ping-pong limit for its hops — all measured in one run,
// side by side, because absolute times drift on shared machines.
//
//   build/bin/bench-lockstep [--seconds S] [--scenario FILE]
//
// The lockstep step's critical path is three messages (desired_t -> command_t -> ack_t ->
// next desired_t; docs/lockstep.md), so its limit is 2/3 of the round trips per second.
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "lockstep/runtime.h"

namespace fs = std::filesystem;

namespace {

/// Round trips per second between two processes on one udpm URL (payload of `bytes` bytes).
double PingPong(const std::string& url, int round_trips, int bytes) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    lcm::LCM lcm(url);
    struct Echo {
      lcm::LCM* lcm;
      void On(const lcm::ReceiveBuffer* rb, const std::string&) {
        lcm->publish("PONG", rb->data, rb->data_size);
      }
    } echo{&lcm};
    lcm.subscribe("PING", &Echo::On, &echo);
    for (;;) lcm.handle();
  }
  lcm::LCM lcm(url);
  struct Counter {
    int n = 0;
    void On(const lcm::ReceiveBuffer*, const std::string&) { ++n; }
  } counter;
  lcm.subscribe("PONG", &Counter::On, &counter);
  std::vector<std::uint8_t> payload(bytes, 0x5a);
  // Warm up until the echo process is subscribed.
  while (counter.n == 0) {
    lcm.publish("PING", payload.data(), bytes);
    lcm.handleTimeout(20);
  }
  counter.n = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < round_trips; ++i) {
    lcm.publish("PING", payload.data(), bytes);
    const int before = counter.n;
    while (counter.n == before) {
      if (lcm.handleTimeout(1000) <= 0) break;  // a lost datagram: count it as slow
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ::kill(pid, SIGTERM);
  ::waitpid(pid, nullptr, 0);
  return round_trips / s;
}

double LockstepRate(const fs::path& bin, const fs::path& scenario, const std::string& transport,
                    const fs::path& out) {
  fs::remove_all(out);
  const std::string cmd = fmt::format("{}/rths-run {} --transport {} --out {} --quiet > /dev/null",
                                      bin.string(), scenario.string(), transport, out.string());
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "bench: %s failed\n", cmd.c_str());
    return 0.0;
  }
  const auto j = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  return j["steps_per_s"].get<double>();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-lockstep: LCM ping-pong vs lockstep steps/s on udpm and memq, one run"};
  double seconds = 5.0;
  std::string scenario;
  app.add_option("--seconds", seconds, "simulated seconds per lockstep run")->capture_default_str();
  app.add_option("--scenario", scenario, "base scenario (default: scenarios/default.toml)");
  CLI11_PARSE(app, argc, argv);

  const fs::path bin = fs::read_symlink("/proc/self/exe").parent_path();
  if (scenario.empty()) scenario = (bin / "../../scenarios/default.toml").lexically_normal().string();
  if (const auto hint = rths::lockstep::CheckMulticastRoute(); !hint.empty()) {
    std::fprintf(stderr, "bench: %s\n", hint.c_str());
    return 3;
  }
  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_bench_{}", ::getpid());
  fs::create_directories(tmp);
  // The default scenario, shortened.
  std::string text;
  {
    std::ifstream in(scenario);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("duration_s", 0) == 0) line = fmt::format("duration_s = {}", seconds);
      text += line + "\n";
    }
  }
  const fs::path scen = tmp / "bench.toml";
  std::ofstream(scen) << text;

  const int port = 7600 + ::getpid() % 300;
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", port);
  const double rt = PingPong(url, 20000, 160);
  const double udpm = LockstepRate(bin, scen, "udpm", tmp / "udpm");
  const double memq = LockstepRate(bin, scen, "memq", tmp / "memq");
  const double limit = rt * 2.0 / 3.0;
  std::printf("LCM udpm ping-pong            %10.0f round trips/s (160-byte payload)\n", rt);
  std::printf("lockstep limit (3 hops/step)  %10.0f steps/s\n", limit);
  std::printf("lockstep udpm (5 processes)   %10.0f steps/s  = %.2f x limit, %.2f x real time\n", udpm,
              udpm / limit, udpm * 0.0005);
  std::printf("lockstep memq (1 process)     %10.0f steps/s  = %.2f x udpm\n", memq, memq / udpm);
  std::printf("target >= 4096 steps/s on udpm: %s\n", udpm >= 4096 ? "met" : "NOT met");
  fs::remove_all(tmp);
  return 0;
}
