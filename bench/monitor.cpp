// bench-monitor: does watching a run slow it down? The same run, side by side and repeated:
// without a monitor, with `rths run --watch` (the monitor listening, no browser), with a headless
// Chromium showing the monitor's page for the whole run, and with the same Chromium on a blank page
// (what a browser on the run's own machine costs by itself, page or not). Prints each run's steps/s (from
// its summary.json), the medians and their ratios to the unwatched run (machines are shared and
// noisy: only ratios from one invocation mean anything).
//
//   build/bin/bench-monitor [--duration-s S] [--repeat N] [--scenario FILE] [--port-per-channel]
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "../tests/support/chromium_pipe.h"
#include "signal/stats.h"

namespace fs = std::filesystem;

namespace {

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

using rths::signal::Median;  // timings: the middle one, or the mean of the two middle ones

enum class Browser { kNone, kMonitorPage, kBlankPage };

/// One run of `rths-run ARGS --out DIR`; with a browser, a headless Chromium shows the monitor's
/// page (the run must have --watch) or a blank page from the moment the monitor's address is
/// printed to the run's end. Returns the run's steps/s, or a negative number if it failed.
double Run(const std::string& run_cmd, const fs::path& dir, Browser browser) {
  const fs::path out_txt = dir.string() + ".txt";
  const std::string cmd = "exec " + run_cmd + " --out " + dir.string() + " > " + out_txt.string() + " 2>&1";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::unique_ptr<rths_test::ChromiumPipe> chromium;
  if (browser != Browser::kNone) {
    const std::regex line("monitor +(http://\\S+)");
    std::string url;
    for (int i = 0; i < 600 && url.empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      std::smatch m;
      const std::string text = Slurp(out_txt);
      if (std::regex_search(text, m, line)) url = m[1];
    }
    if (!url.empty()) {
      chromium = std::make_unique<rths_test::ChromiumPipe>(dir.string() + "-chromium");
      chromium->Open(browser == Browser::kMonitorPage ? url : "about:blank");
    }
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  chromium.reset();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "bench-monitor: %s failed:\n%s\n", cmd.c_str(), Slurp(out_txt).c_str());
    return -1;
  }
  return nlohmann::json::parse(Slurp(dir / "summary.json")).value("steps_per_s", 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-monitor: steps/s of a run without a monitor, with `run --watch`, and with a browser on "
               "the monitor's page, side by side"};
  double duration_s = 10;
  int repeat = 3;
  bool port_per_channel = false;
  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  std::string scenario = (bin_dir.parent_path().parent_path() / "scenarios" / "default.toml").string();
  app.add_option("--duration-s", duration_s, "simulated seconds per run")->check(CLI::Range(0.5, 600.0));
  app.add_option("--repeat", repeat, "runs of each kind")->check(CLI::Range(1, 50));
  app.add_option("--scenario", scenario, "the scenario");
  app.add_flag("--port-per-channel", port_per_channel, "runs with a port per channel");
  CLI11_PARSE(app, argc, argv);

  const fs::path tmp = fs::temp_directory_path() / fmt::format("rths_bench_monitor_{}", ::getpid());
  fs::create_directories(tmp);
  const std::string base = fmt::format("{}/rths-run {} --compact --quiet --set run.duration_s={}{}",
                                       bin_dir.string(), scenario, duration_s,
                                       port_per_channel ? " --port-per-channel" : "");
  struct Kind {
    const char* name;
    std::string args;
    Browser browser;
    std::vector<double> rates;
  };
  std::vector<Kind> kinds = {{"no monitor", "", Browser::kNone, {}},
                             {"--watch, no browser", " --watch --watch-port 0", Browser::kNone, {}},
                             {"--watch, Chromium on the page", " --watch --watch-port 0", Browser::kMonitorPage, {}},
                             {"--watch, Chromium on about:blank", " --watch --watch-port 0", Browser::kBlankPage, {}}};
  std::printf("bench-monitor: %s, %g s runs, %d of each kind, interleaved\n", scenario.c_str(), duration_s, repeat);
  for (int r = 0; r < repeat; ++r) {
    for (std::size_t n = 0; n < kinds.size(); ++n) {
      auto& k = kinds[n];
      const double rate = Run(base + k.args, tmp / fmt::format("run{}_{}", r, n), k.browser);
      if (rate < 0) return 1;
      k.rates.push_back(rate);
      std::printf("  %-32s %8.0f steps/s\n", k.name, rate);
      std::fflush(stdout);
      fs::remove_all(tmp / fmt::format("run{}_{}", r, n));
    }
  }
  const double none = Median(kinds[0].rates);
  std::printf("\n%-34s %14s %10s\n", "", "median steps/s", "ratio");
  for (const auto& k : kinds) std::printf("%-34s %14.0f %10.3f\n", k.name, Median(k.rates), Median(k.rates) / none);
  fs::remove_all(tmp);
  return 0;
}
