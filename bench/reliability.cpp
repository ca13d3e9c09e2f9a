// bench-reliability: what faults cost, measured side by side in one run (absolute times drift
// on shared machines; the ratios and counts are what to read).
//
//   build/bin/bench-reliability [--seconds S] [--kills N]
//
// 1. Time from an outside `kill -9` of a participant to the supervisor's exit (the run torn
//    down, summary written), for each role, N times each.
// 2. The default scenario with 5 % of each fault (drop, duplicate, delay, reorder) on every
//    channel, and with 2 kB socket buffers: re-requests, repaired messages, and steps/s as a
//    fraction of the clean run's.
#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "lockstep/step_table.h"
#include "lockstep/transport.h"
#include "signal/stats.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

/// The pid of the child of `parent` whose command name is `comm`, or -1.
pid_t ChildNamed(pid_t parent, const std::string& comm) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.empty() || !std::isdigit(static_cast<unsigned char>(name[0]))) continue;
    std::ifstream in(e.path() / "stat");
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto open = all.find('('), close = all.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close + 4 > all.size()) continue;
    const std::string c = all.substr(open + 1, close - open - 1);
    int ppid = 0;
    char state = 0;
    if (std::sscanf(all.c_str() + close + 2, "%c %d", &state, &ppid) != 2) continue;
    if (ppid == parent && c == comm) return std::stoi(name);
  }
  return -1;
}

/// Starts `rths-run ARGS` in the background (output to /dev/null); returns its pid.
pid_t Start(const fs::path& bin, const std::string& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string cmd = fmt::format("exec {}/rths-run {} > /dev/null 2>&1", bin.string(), args);
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

/// Seconds from SIGKILL of `role` (once `steps` steps are on disk) to the supervisor's exit.
double TimeToNotice(const fs::path& bin, const fs::path& scen, const fs::path& out, const std::string& role) {
  fs::remove_all(out);
  const pid_t sup = Start(bin, fmt::format("{} --out {}", scen.string(), out.string()));
  pid_t victim = -1;
  for (int i = 0; i < 2000; ++i) {  // wait for the run to be well under way
    if (fs::exists(out / "signals.csv") && fs::file_size(out / "signals.csv") > 200000) {
      victim = ChildNamed(sup, "rths-" + role);
      if (victim > 0) break;
    }
    ::usleep(5000);
  }
  if (victim <= 0) {
    ::kill(sup, SIGINT);
    ::waitpid(sup, nullptr, 0);
    return -1.0;
  }
  const auto t0 = Clock::now();
  ::kill(victim, SIGKILL);
  int status = 0;
  ::waitpid(sup, &status, 0);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct RunFigures {
  double steps_per_s = 0;
  long long rerequests = 0, repaired = 0, injected = 0;
  bool ok = false;
};

RunFigures Run(const fs::path& bin, const fs::path& scen, const std::string& transport, const fs::path& out) {
  fs::remove_all(out);
  const std::string cmd = fmt::format("{}/rths-run {} --transport {} --out {} --quiet > /dev/null 2>&1",
                                      bin.string(), scen.string(), transport, out.string());
  RunFigures f;
  f.ok = std::system(cmd.c_str()) == 0;
  if (!fs::exists(out / "summary.json")) return f;
  const auto j = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  f.steps_per_s = j.value("steps_per_s", 0.0);
  f.rerequests = j["link"]["rerequests"].get<long long>();
  f.repaired = j["link"]["repaired"].get<long long>();
  const auto& in = j["link"]["injected"];
  f.injected = in["dropped"].get<long long>() + in["duplicated"].get<long long>() + in["delayed"].get<long long>() +
               in["reordered"].get<long long>();
  return f;
}

std::string Shortened(const std::string& scenario, double seconds, const std::string& extra) {
  std::ifstream in(scenario);
  std::string line, text;
  while (std::getline(in, line)) {
    if (line.rfind("duration_s", 0) == 0) line = fmt::format("duration_s = {}", seconds);
    if (line.rfind("rerequest_ms", 0) == 0) line = "rerequest_ms = 10.0";
    text += line + "\n";
  }
  return text + extra;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-reliability: time to notice a killed participant; cost of message faults"};
  double seconds = 4.0;
  int kills = 5;
  app.add_option("--seconds", seconds, "simulated seconds of the fault runs")->capture_default_str();
  app.add_option("--kills", kills, "kills per role")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (const auto hint = rths::lockstep::CheckMulticastRoute(); !hint.empty()) {
    std::fprintf(stderr, "bench: %s\n", hint.c_str());
    return 3;
  }
  const fs::path bin = fs::read_symlink("/proc/self/exe").parent_path();
  const std::string scenario = (bin / "../../scenarios/default.toml").lexically_normal().string();
  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_bench_rel_{}", ::getpid());
  fs::create_directories(tmp);

  // 1. Kill a participant from outside; the stall budget (10 s) is what polling would cost.
  const fs::path long_scen = tmp / "long.toml";
  std::ofstream(long_scen) << Shortened(scenario, 20.0, "");
  std::printf("time from kill -9 to the supervisor's exit (run torn down, summary written), %d kills each:\n",
              kills);
  for (const std::string_view name : rths::lockstep::kRoster) {
    const std::string role(name);
    std::vector<double> t;
    for (int i = 0; i < kills; ++i) {
      const double s = TimeToNotice(bin, long_scen, tmp / "kill", role);
      if (s >= 0) t.push_back(s);
    }
    std::sort(t.begin(), t.end());
    if (t.empty()) {
      std::printf("  %-11s  (could not kill it in time)\n", role.c_str());
      continue;
    }
    std::printf("  %-11s  min %6.1f ms   median %6.1f ms   max %6.1f ms   (stall budget: 10000 ms)\n", role.c_str(),
                1e3 * t.front(), 1e3 * rths::signal::Median(t), 1e3 * t.back());
  }

  // 2. Message faults: the same run clean, with 5 % of each fault, with 2 kB socket buffers.
  const fs::path clean = tmp / "clean.toml", faulty = tmp / "faulty.toml", small = tmp / "small.toml";
  std::ofstream(clean) << Shortened(scenario, seconds, "");
  std::ofstream(faulty) << Shortened(scenario, seconds,
                                     "\n[faults]\ndrop = 0.05\nduplicate = 0.05\ndelay = 0.05\nreorder = 0.05\n"
                                     "delay_ms = 5.0\nseed = 3\n");
  std::ofstream(small) << Shortened(scenario, seconds, "\n[faults]\nrecv_buf_bytes = 2048\n");
  const long long steps = static_cast<long long>(seconds / 0.0005);
  std::printf("\n%lld steps each, re-requests after 10 ms                steps/s   x clean  injected  re-requests  repaired\n",
              steps);
  for (const char* transport : {"memq", "udpm"}) {
    const RunFigures c = Run(bin, clean, transport, tmp / "clean");
    const RunFigures f = Run(bin, faulty, transport, tmp / "faulty");
    std::printf("  %s clean                                          %8.0f   %6.2f  %8lld  %11lld  %8lld\n", transport,
                c.steps_per_s, 1.0, c.injected, c.rerequests, c.repaired);
    std::printf("  %s 5 %% drop + duplicate + delay + reorder%s       %8.0f   %6.2f  %8lld  %11lld  %8lld\n",
                transport, f.ok ? "" : " FAILED", f.steps_per_s, c.steps_per_s > 0 ? f.steps_per_s / c.steps_per_s : 0,
                f.injected, f.rerequests, f.repaired);
    if (std::string(transport) == "udpm") {
      const RunFigures b = Run(bin, small, transport, tmp / "small");
      std::printf("  udpm 2 kB socket buffers%s                          %8.0f   %6.2f  %8lld  %11lld  %8lld\n",
                  b.ok ? "" : " FAILED", b.steps_per_s, c.steps_per_s > 0 ? b.steps_per_s / c.steps_per_s : 0,
                  b.injected, b.rerequests, b.repaired);
    }
  }
  fs::remove_all(tmp);
  return 0;
}
