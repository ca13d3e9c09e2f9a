// bench-realtime: paced (real-time) runs of the default scenario on both transports, side by
// side in one invocation, with their step-latency percentiles, deadline misses and a latency
// histogram (PNG). Not a test: these machines are shared and noisy; read the figures as what
// this host achieved now (docs/realtime.md).
//
//   build/bin/bench-realtime [--seconds S] [--scenario FILE] [--out DIR] [--transports memq,udpm]
//                            [--spin-us US] [--cpu N] [--linear-plant] [--external-priority P]
//
// A transport "mixed:PLANT" is a mixed run (the built-in participants in one process, bridged on
// udpm) with an external plant: builtin (rths-plant), java (examples/java_plant), python
// (examples/python_plant); e.g. --transports memq,mixed:java,mixed:python,udpm. The Java and
// Python plants model the linear servo without a specimen: --linear-plant sets every row's
// scenario to that plant (plant.kind = "linear", actuator = "avg", specimen = "none"), so the
// rows compare like with like. --spin-us and --cpu set [realtime] spin_us and cpu for every row.
// Each row's miss rate is also given as a ratio to the host's own (the "sleep" row).
//
// First, the host's own wake-up lateness (a cyclictest-like loop that only sleeps to absolute
// deadlines, at most 20 s): misses that this row shows too are the host's, not rths's.
// Each run is `rths run --realtime` of the scenario with run.duration_s = S (default 60), so a
// run takes S seconds of wall time. Prints one row per transport and writes DIR/latency.png and
// DIR/<transport>/summary.json (DIR default: runs/<time>-bench-realtime).
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "external_run.h"
#include "io/output_folder.h"
#include "lockstep/realtime.h"
#include "io/plot.h"
#include "scenario/scenario.h"

namespace fs = std::filesystem;

namespace {

/// The host's own wake-up jitter, as cyclictest measures it: a SCHED_FIFO thread (if permitted)
/// sleeping to absolute deadlines every period_s for seconds; how late each wake-up was.
rths::lockstep::LatencyHistogram WakeUpBaseline(double period_s, double seconds, const rths::scenario::Scenario& s,
                                                std::int64_t* periods_missed) {
  rths::lockstep::LatencyHistogram h;
  std::thread t([&] {
    rths::lockstep::EnterRealtime(s.realtime.sched_fifo, s.realtime.priority, false);
    timespec next{};
    ::clock_gettime(CLOCK_MONOTONIC, &next);
    const auto period_ns = static_cast<long>(period_s * 1e9);
    const auto n = static_cast<std::int64_t>(seconds / period_s);
    for (std::int64_t k = 0; k < n; ++k) {
      next.tv_nsec += period_ns;
      while (next.tv_nsec >= 1000000000) {
        next.tv_nsec -= 1000000000;
        ++next.tv_sec;
      }
      while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr) == EINTR) {
      }
      timespec now{};
      ::clock_gettime(CLOCK_MONOTONIC, &now);
      const double late = static_cast<double>(now.tv_sec - next.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec - next.tv_nsec);
      h.Add(std::max(late, 0.0));
      if (late > period_s) ++*periods_missed;
    }
  });
  t.join();
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-realtime: 60 s paced runs on memq and udpm; latency percentiles, misses, histogram PNG"};
  double seconds = 60.0;
  std::string scenario_path = "scenarios/default.toml", out_arg, transports_arg = "memq,udpm";
  app.add_option("--seconds", seconds, "simulated (= wall) seconds per run")->capture_default_str();
  app.add_option("--scenario", scenario_path, "scenario to pace")->capture_default_str();
  app.add_option("--out", out_arg, "output folder (default: runs/<time>-bench-realtime)");
  app.add_option("--transports", transports_arg, "comma-separated: memq, udpm, mixed:builtin|java|python")
      ->capture_default_str();
  double spin_us = 0;
  int cpu = -1;
  bool linear_plant = false;
  app.add_option("--spin-us", spin_us, "[realtime] spin_us of every run (busy-wait before each release)")
      ->capture_default_str();
  app.add_option("--cpu", cpu, "[realtime] cpu of every run (-1: no pinning)")->capture_default_str();
  int external_priority = 0;
  app.add_option("--external-priority", external_priority,
                 "run the external plants of mixed rows under SCHED_FIFO at this priority (chrt -f), as a lab "
                 "would run its own participant; 0: the normal scheduler")
      ->check(CLI::Range(0, 99));
  app.add_flag("--linear-plant", linear_plant, "every row on the linear servo without a specimen (as the Java and "
                                               "Python plants model)");
  CLI11_PARSE(app, argc, argv);

  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  fs::path out = out_arg;
  if (out.empty()) out = rths::io::NewOutputFolder("bench-realtime");
  fs::create_directories(out);
  std::vector<std::string> sets;
  if (linear_plant) sets = {"plant.kind=\"linear\"", "plant.actuator=\"avg\"", "plant.specimen=\"none\""};
  rths::scenario::Scenario s = rths::scenario::LoadScenario(scenario_path, sets);
  s.run.duration_s = seconds;
  s.realtime.spin_us = spin_us;
  s.realtime.cpu = cpu;
  s.run.name = "bench_realtime";
  // Written next to the original, so relative paths in it (structure or record files) still resolve.
  const fs::path paced = fs::path(scenario_path).parent_path() / fmt::format(".bench-realtime-{}.toml", ::getpid());
  std::ofstream(paced) << rths::scenario::ToToml(s);

  std::vector<std::string> transports;
  std::stringstream ss(transports_arg);
  for (std::string t; std::getline(ss, t, ',');) transports.push_back(t);

  std::printf("bench-realtime: %s%s paced at %g Hz for %g s per transport, on %ld CPUs, spin_us %g, cpu %d, external "
              "plants %s\n",
              scenario_path.c_str(), linear_plant ? " (linear plant, no specimen)" : "", 1.0 / s.run.dt_s, seconds,
              static_cast<long>(std::thread::hardware_concurrency()), spin_us, cpu,
              external_priority > 0 ? fmt::format("SCHED_FIFO {}", external_priority).c_str() : "normal scheduler");
  std::printf("%-14s %8s %8s %9s %8s %10s %8s %10s %8s  %s\n", "", "steps", "misses", "miss %", "x host", "p50 us",
              "p99 us", "p99.9 us", "max us", "set-up");
  double host_miss = 0;  // the host's own miss fraction (at least one miss in its steps)
  {
    std::int64_t missed = 0;
    const auto h = WakeUpBaseline(s.run.dt_s, std::min(seconds, 20.0), s, &missed);
    const double n = static_cast<double>(std::max<std::int64_t>(h.count(), 1));
    host_miss = static_cast<double>(std::max<std::int64_t>(missed, 1)) / n;
    std::printf("%-14s %8lld %8lld %8.4f%% %8s %10.0f %8.0f %10.0f %8.0f  wake-up lateness alone (no work; "
                "cyclictest-like)%s\n",
                "sleep", static_cast<long long>(h.count()), static_cast<long long>(missed),
                100.0 * static_cast<double>(missed) / n, "1", 1e6 * h.Quantile(0.5), 1e6 * h.Quantile(0.99),
                1e6 * h.Quantile(0.999), 1e6 * h.max_s(), missed == 0 ? " (0 misses: ratios use 1)" : "");
  }
  rths::io::Figure fig;
  fig.name = "latency";
  fig.title = fmt::format("Step latency (request to barrier), paced at {:g} Hz for {:g} s", 1.0 / s.run.dt_s, seconds);
  auto panel = rths::io::MakePanel("", "Latency [us] (log-spaced bins, 100 per decade)",
                                       "Steps per bin (log scale)");
  panel.log_x = true;
  panel.log_y = true;
  int code = 0;
  int port = 21000 + ::getpid() % 4000 * 2;
  for (const auto& t : transports) {
    const bool mixed = t.rfind("mixed:", 0) == 0;
    const fs::path dir = out / (mixed ? "mixed_" + t.substr(6) : t);
    int rc = 0;
    if (mixed) {
      rc = rths_bench::RunWithExternalPlant(bin_dir, "--realtime --quiet", paced, dir, t.substr(6), s.steps(),
                                            s.run.dt_s, port++,
                                            external_priority > 0 ? fmt::format("chrt -f {}", external_priority) : "");
    } else {
      const std::string cmd = fmt::format("{}/rths-run --realtime --quiet --transport {} --out {} {} > {}/stdout.txt 2>&1",
                                          bin_dir.string(), t, dir.string(), paced.string(), out.string());
      rc = std::system(cmd.c_str());
    }
    nlohmann::json j;
    try {
      std::ifstream in(dir / "summary.json");
      j = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      std::printf("%-14s run failed (exit %d): %s\n", t.c_str(), rc, e.what());
      code = 1;
      continue;
    }
    if (!j.contains("realtime") || !j["realtime"].contains("steps")) {
      std::printf("%-14s run failed: %s\n", t.c_str(), j.value("stopped", std::string("no realtime figures")).c_str());
      code = 1;
      continue;
    }
    const auto& rt = j["realtime"];
    const auto steps = rt["steps"].get<std::int64_t>();
    const auto misses = rt["deadline_misses"].get<std::int64_t>();
    std::printf("%-14s %8lld %8lld %8.4f%% %8.1f %10.0f %8.0f %10.0f %8.0f  FIFO %d/%d, locked %d/%d%s\n", t.c_str(),
                static_cast<long long>(steps), static_cast<long long>(misses),
                100.0 * rt["miss_fraction"].get<double>(), rt["miss_fraction"].get<double>() / host_miss,
                rt["latency_p50_us"].get<double>(),
                rt["latency_p99_us"].get<double>(), rt["latency_p999_us"].get<double>(),
                rt["latency_max_us"].get<double>(), rt["sched_fifo_processes"].get<int>(),
                rt["processes"].get<int>(), rt["memory_locked_processes"].get<int>(), rt["processes"].get<int>(),
                rt["setup_notes"].get<std::string>().empty() ? "" : " (see summary.json setup_notes)");
    auto series = rths::io::MakeSeries(fmt::format("{}: p99.9 {:.0f} us, {} misses of {}", t,
                                                       rt["latency_p999_us"].get<double>(), misses, steps));
    series.with = "steps";
    for (const auto& b : rt["latency_histogram_us"]) {
      const double lo = b[0].get<double>(), hi = b[1].get<double>();
      if (lo <= 0 || hi <= 0) continue;  // under- and overflow bins
      series.x.push_back(std::sqrt(lo * hi));
      series.y.push_back(b[2].get<double>());
    }
    panel.series.push_back(std::move(series));
  }
  {
    auto deadline = rths::io::MakeSeries(fmt::format("deadline: dt = {:g} us", 1e6 * s.run.dt_s), "black", 2);
    deadline.x = {1e6 * s.run.dt_s, 1e6 * s.run.dt_s};
    deadline.y = {1.0, seconds / s.run.dt_s};
    panel.series.push_back(std::move(deadline));
  }
  fs::remove(paced);
  fig.panels.push_back(panel);
  try {
    const auto files = rths::io::Plot(fig, out);
    std::printf("histogram: %s\n", files.png.string().c_str());
  } catch (const std::exception& e) {
    std::printf("no histogram: %s\n", e.what());
  }
  std::printf("output: %s\n", out.string().c_str());
  return code;
}
