#pragma once
// A recorded run played by the plain `lcm-logplayer` into `rths-plant --follow` (docs/replay.md),
// optionally with every core kept busy: what tests/participants/replay_test.cpp checks and bench/follow.cpp
// tabulates.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace rths_test {

namespace follow_fs = std::filesystem;

/// `n` busy loops (one per core: `sh -c 'while :; do :; done'`) for as long as it lives.
class BusyLoops {
 public:
  explicit BusyLoops(int n) {
    for (int i = 0; i < n; ++i) {
      const pid_t pid = ::fork();
      if (pid == 0) {
        ::execl("/bin/sh", "sh", "-c", "while :; do :; done", static_cast<char*>(nullptr));
        ::_exit(127);
      }
      if (pid > 0) pids_.push_back(pid);
    }
  }
  ~BusyLoops() {
    for (const pid_t pid : pids_) ::kill(pid, SIGKILL);
    for (const pid_t pid : pids_) ::waitpid(pid, nullptr, 0);
  }
  BusyLoops(const BusyLoops&) = delete;
  BusyLoops& operator=(const BusyLoops&) = delete;
  int size() const { return static_cast<int>(pids_.size()); }

 private:
  std::vector<pid_t> pids_;
};

/// One follow replay: the recorded run in `recording` (scenario.toml, log.lcm) played at `speed`
/// on `url` into `bin_dir`/rths-plant --follow `plant_args`, whose files go to `work`.
struct FollowPlay {
  follow_fs::path bin_dir, recording, work;
  std::int64_t run_id = 0;
  std::string url;
  double speed = 1.0;
  std::string plant_args;
};

/// How the plant ended: its exit code, its outcome file's "follow" and what it printed.
struct FollowResult {
  int exit_code = -1;
  nlohmann::json follow;
  std::string printed;
};

inline std::string FollowSlurp(const follow_fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Starts the plant, waits until it has had 1 s to subscribe, plays the log with lcm-logplayer
/// (every channel the plant reads, not its own) and waits for the plant to go idle and exit.
inline FollowResult PlayFollow(const FollowPlay& p) {
  follow_fs::create_directories(p.work);
  const follow_fs::path out = p.work / "plant.out";
  const std::string plant = "exec " + (p.bin_dir / "rths-plant").string() + " --follow --scenario " +
                            (p.recording / "scenario.toml").string() + " --lcm-url '" + p.url + "' --run-id " +
                            std::to_string(p.run_id) + " --out " + p.work.string() + " " + p.plant_args + " > " +
                            out.string() + " 2>&1";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", plant.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Its outcome file is reserved first thing; then it reads the scenario and subscribes.
  const follow_fs::path outcome = p.work / "logs" / "plant.json";
  for (int i = 0; i < 300 && !follow_fs::exists(outcome); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  char speed[32];
  std::snprintf(speed, sizeof speed, "%g", p.speed);
  const std::string play = "lcm-logplayer --speed=" + std::string(speed) +
                           " -e '^RTHS_(DESIRED|COMMAND|CURRENT)$' --lcm-url='" + p.url + "' " +
                           (p.recording / "log.lcm").string() + " > " + (p.work / "logplayer.out").string() + " 2>&1";
  (void)std::system(play.c_str());
  int status = 0;
  ::waitpid(pid, &status, 0);
  FollowResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.printed = FollowSlurp(out);
  const std::string text = FollowSlurp(outcome);
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_object() && j.contains("follow")) r.follow = j.at("follow");
  return r;
}

}  // namespace rths_test
