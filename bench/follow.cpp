// bench-follow: how much of a recorded run survives `lcm-logplayer` into `rths-plant --follow`
// (docs/replay.md)? One recorded run (the default scenario), played at each speed, on a quiet
// machine, with every core busy (one busy loop per core) and heavily loaded (six per core: a load
// average near 12 on 2 cores), with LCM's own defaults (a queue of 30
// messages per channel, the system's socket receive buffer: what follow mode had before) and with
// follow mode's (a deep queue, a 4 MiB receive buffer). Prints the plant's steps exact / held /
// resumed after a hold / unseen for each. Under the old behaviour the plant stopped at the first
// lost input, so its "exact" count is what it used to answer.
//
//   build/bin/bench-follow [--duration-s S] [--speeds 0.5,1,2] [--scenario FILE] [--loads quiet,busy,heavy]
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "../tests/support/follow_replay.h"

namespace fs = std::filesystem;

namespace {

/// The run id a recorded run's summary.json gives.
std::int64_t RunIdOf(const fs::path& run) {
  const auto j = nlohmann::json::parse(rths_test::FollowSlurp(run / "summary.json"));
  return j.at("run_id").get<std::int64_t>();
}

struct Config {
  const char* name;
  const char* plant_args;
};

}  // namespace

int main(int argc, char** argv) {
  double duration_s = 20.0;
  std::vector<double> speeds = {0.5, 1.0, 2.0};
  std::vector<std::string> loads = {"quiet", "busy", "heavy"};
  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  std::string scenario = (bin_dir.parent_path().parent_path() / "scenarios" / "default.toml").string();
  CLI::App app{"bench-follow: lcm-logplayer into rths-plant --follow, quiet and loaded, before and after"};
  app.add_option("--duration-s", duration_s, "the recorded run's duration [s]")->check(CLI::Range(0.5, 600.0));
  app.add_option("--speeds", speeds, "lcm-logplayer speeds")->delimiter(',');
  app.add_option("--loads", loads, "quiet, busy (one busy loop per core), heavy (six per core)")->delimiter(',')
      ->check(CLI::IsMember({"quiet", "busy", "heavy"}));
  app.add_option("--scenario", scenario, "the scenario recorded")->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);

  const fs::path work = fs::temp_directory_path() / fmt::format("rths_bench_follow_{}", ::getpid());
  fs::create_directories(work);
  const fs::path rec = work / "recorded";
  const std::string record = fmt::format("{}/rths-run {} --compact --quiet --transport memq --set run.duration_s={} "
                                         "--out {} > {}/record.txt 2>&1",
                                         bin_dir.string(), scenario, duration_s, rec.string(), work.string());
  if (std::system(record.c_str()) != 0) {
    std::fprintf(stderr, "bench-follow: recording failed: %s\n", rths_test::FollowSlurp(work / "record.txt").c_str());
    return 1;
  }
  const std::int64_t run_id = RunIdOf(rec);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  const Config configs[] = {{"LCM defaults (before)", "--follow-queue 30 --follow-recv-buf 0"},
                            {"follow defaults (after)", ""}};
  std::printf("bench-follow: %g s recorded (%s), %d cores; rths-plant --follow fed by lcm-logplayer\n", duration_s,
              scenario.c_str(), cores);
  std::printf("%-6s %-5s %-24s %8s %8s %8s %8s %5s\n", "load", "speed", "queue / receive buffer", "exact", "held",
              "resumed", "unseen", "exit");
  int port = 20000 + (::getpid() * 13) % 20000;
  int i = 0;
  for (const std::string& load : loads) {
    for (const double speed : speeds) {
      for (const Config& c : configs) {
        std::unique_ptr<rths_test::BusyLoops> busy;
        if (load != "quiet") busy = std::make_unique<rths_test::BusyLoops>(load == "busy" ? cores : 6 * cores);
        const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", port++);
        const auto r = rths_test::PlayFollow(
            {bin_dir, rec, work / fmt::format("play{}", i++), run_id, url, speed, std::string(c.plant_args)});
        busy.reset();
        if (!r.follow.is_object()) {
          std::printf("%-6s %-5g %-24s plant failed (exit %d): %s\n", load.c_str(), speed, c.name, r.exit_code,
                      r.printed.c_str());
          continue;
        }
        std::printf("%-6s %-5g %-24s %8lld %8lld %8lld %8lld %5d\n", load.c_str(), speed, c.name,
                    r.follow["exact"].get<long long>(), r.follow["held"].get<long long>(),
                    r.follow["resumed"].get<long long>(), r.follow["unseen"].get<long long>(), r.exit_code);
        std::fflush(stdout);
      }
    }
  }
  fs::remove_all(work);
  return 0;
}
