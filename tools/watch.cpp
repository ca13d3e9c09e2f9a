// rths-watch: `rths watch`, the live monitor of a run (monitor/monitor.h, docs/monitor.md): listens
// to the run's LCM traffic as an ordinary lossy listener and serves a page with its scrolling
// plots, status and an Abort button, until interrupted (or, --exit-at-end, until the run ends).
#include <csignal>
#include <cstdio>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "core/exit_code.h"
#include "lockstep/transport.h"
#include "watch_flags.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

/// A line on the terminal when the run's phase changes.
void SayPhase(const rths::monitor::LiveStatus& s) {
  std::string line = "rths watch: run " + std::to_string(s.run_id) + " " + s.phase;
  if (s.phase == "aborted") line += " by " + s.abort_by + ": " + s.abort_reason;
  if (s.phase == "completed" || s.phase == "aborted") line += " (" + std::to_string(s.last_k + 1) + " steps heard)";
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths watch: watch a run live in a browser (scrolling r, u, y, tracking error, force, current; "
               "step counter and rate; the clock's latency and misses when paced; the safety limits) with an ABORT "
               "button. It listens like any LCM listener to what the run's clock publishes and never slows the run "
               "down. `rths run` prints the run's --lcm-url; "
               "`rths run --watch` starts a monitor itself"};
  std::string url;
  bool paced = false, exit_at_end = false;
  rths::tools::WatchFlags flags;
  app.add_option("--lcm-url", url, "the run's udpm URL, as `rths run` printed it (udpm://GROUP:PORT?ttl=0...)")
      ->required();
  flags.Add(app, "--");
  // Before the clock fed the monitor, the user said whether the run was paced; its records say so now.
  app.add_flag("--paced", paced, "(ignored: the run's clock says whether it is paced)")->group("");
  app.add_flag("--exit-at-end", exit_at_end, "exit 2 s after the run completes or is aborted");
  rths::tools::NameCommand(app, "watch");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  if (!rths::lockstep::UdpmUrl::Parse(url)) {
    std::fprintf(stderr, "rths watch: --lcm-url %s: not a udpm:// URL (e.g. udpm://239.255.76.67:7667?ttl=0)\n",
                 url.c_str());
    return rths::kExitUsage;
  }
  std::unique_ptr<rths::monitor::Monitor> monitor;
  try {
    std::printf("rths watch: %s\n", url.c_str());
    monitor = flags.Start(url, "rths monitor", "watch", stdout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths watch: %s\n", e.what());
    return rths::kExitUsage;
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::string phase = "waiting";
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto s = monitor->Status();
    if (s.phase == phase) continue;
    phase = s.phase;
    SayPhase(s);
    if (exit_at_end && (phase == "completed" || phase == "aborted")) {
      std::this_thread::sleep_for(std::chrono::seconds(2));  // the page gets the end
      break;
    }
  }
  monitor->Stop();
  return 0;
}
