// rths-run: the supervisor behind `rths run` (docs/lockstep.md).
//
// Validates the scenario, makes the output folder, starts the five participants — as
// separate processes on udpm:// (one UDP port per run, ttl=0) or in this process on
// memq:// — waits for them, tears the group down when one fails, and writes summary.json
// from the event log. Exits non-zero naming the participant that failed.
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/run_log.h"
#include "lockstep/runtime.h"
#include "participants/factory.h"
#include "participants/group.h"
#include "scenario/scenario.h"

namespace fs = std::filesystem;
using rths::lockstep::ExitCode;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

using rths::participants::Outcome;

std::string LastLine(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

int FreeUdpPort() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) throw rths::Error("rths run", "cannot create a UDP socket to pick a port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw rths::Error("rths run", "cannot pick a free UDP port");
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

fs::path DefaultOutDir(const std::string& name) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  fs::path base = fs::path("runs") / fmt::format("{}-{}", stamp, name);
  fs::path p = base;
  for (int i = 2; fs::exists(p); ++i) p = base.string() + "-" + std::to_string(i);
  return p;
}

std::vector<Outcome> RunUdpm(const rths::scenario::Scenario&, const std::string& scenario_path,
                             std::int64_t run_id, const fs::path& out, const fs::path& bin_dir,
                             const std::vector<rths::participants::RoleFault>& faults,
                             std::string* url_out) {
  if (const std::string hint = rths::lockstep::CheckMulticastRoute(); !hint.empty()) {
    throw rths::Error("rths run", hint);
  }
  const int port = FreeUdpPort();
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", port);
  *url_out = url;
  fs::create_directories(out / "logs");
  std::map<pid_t, Outcome> children;
  std::map<pid_t, bool> exited;
  for (const char* role : {"logger", "plant", "controller", "semiactive", "integrator"}) {
    const fs::path exe = bin_dir / fmt::format("rths-{}", role);
    if (!fs::exists(exe)) {
      throw rths::Error("rths run", fmt::format("{} is missing: build first (see README)", exe.string()));
    }
    std::vector<std::string> args{exe.string(),     "--scenario", scenario_path, "--lcm-url", url,
                                  "--run-id",       std::to_string(run_id),      "--out",
                                  out.string()};
    for (const auto& f : faults) {
      if (f.role != role) continue;
      for (auto [flag, k] : {std::pair{"--fault-drop", f.faults.drop_first_request_at},
                             {"--fault-stall", f.faults.stall_at},
                             {"--fault-throw", f.faults.throw_at},
                             {"--fault-crash", f.faults.crash_at}}) {
        if (k < 0) continue;
        args.push_back(flag);
        args.push_back(std::to_string(k));
      }
    }
    const fs::path log = out / "logs" / fmt::format("{}.log", role);
    const pid_t pid = ::fork();
    if (pid < 0) throw rths::Error("rths run", "fork failed");
    if (pid == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // never outlive the supervisor
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        ::close(fd);
      }
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      std::fprintf(stderr, "exec %s failed: %s\n", argv[0], std::strerror(errno));
      ::_exit(127);
    }
    children[pid] = Outcome{role, 0, 0, ""};
    exited[pid] = false;
  }

  using Clock = std::chrono::steady_clock;
  std::size_t running = children.size();
  bool tearing_down = false;
  Clock::time_point term_at{}, kill_at{};
  bool termed = false, killed = false;
  while (running > 0) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0 && children.count(pid)) {
      Outcome& o = children[pid];
      exited[pid] = true;
      --running;
      if (WIFSIGNALED(status)) {
        o.signal = WTERMSIG(status);
        o.exit_code = 128 + o.signal;
      } else {
        o.exit_code = WEXITSTATUS(status);
      }
      o.message = LastLine(out / "logs" / fmt::format("{}.log", o.role));
      if (o.exit_code != 0 && !tearing_down) {
        // Let the others notice the ABORT (or the silence) and stop by themselves first.
        tearing_down = true;
        term_at = Clock::now() + std::chrono::seconds(3);
      }
      continue;
    }
    if (g_interrupted && !tearing_down) {
      tearing_down = true;
      term_at = Clock::now();
    }
    const auto now = Clock::now();
    if (tearing_down && !termed && now >= term_at) {
      for (auto& [p, o] : children) {
        if (!exited[p]) ::kill(p, SIGTERM);
      }
      termed = true;
      kill_at = now + std::chrono::seconds(2);
    }
    if (termed && !killed && now >= kill_at) {
      for (auto& [p, o] : children) {
        if (!exited[p]) ::kill(p, SIGKILL);
      }
      killed = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::vector<Outcome> outcomes;
  for (auto& [p, o] : children) outcomes.push_back(o);
  return outcomes;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths run: start a lockstep RTHS run (integrator, controller, plant, semiactive, "
               "logger), wait for it, and write its output folder"};
  std::string scenario_path, default_scenario = "scenarios/default.toml";
  std::string out_arg, transport = "udpm", bin_dir;
  std::vector<std::string> fault_args;
  bool quiet = false;
  app.add_option("scenario", scenario_path, "scenario TOML file (default: scenarios/default.toml)");
  app.add_option("--default-scenario", default_scenario, "used when no scenario is given")->group("");
  app.add_option("--out", out_arg, "output folder (default: a new folder under runs/)");
  app.add_option("--transport", transport, "udpm: one process per participant; memq: one process")
      ->check(CLI::IsMember({"udpm", "memq"}))
      ->capture_default_str();
  app.add_option("--bin-dir", bin_dir, "where the rths-* programs are (default: next to this one)");
  app.add_option("--fault", fault_args, "test only: ROLE:drop|stall|throw|crash:K")->group("");
  app.add_flag("--quiet", quiet, "print only the output folder");
  CLI11_PARSE(app, argc, argv);

  if (scenario_path.empty()) scenario_path = default_scenario;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  std::vector<rths::participants::RoleFault> faults;
  for (const auto& f : fault_args) {
    rths::participants::RoleFault x;
    std::istringstream ss(f);
    std::string kind, k;
    std::getline(ss, x.role, ':');
    std::getline(ss, kind, ':');
    std::getline(ss, k);
    std::int64_t* slot = kind == "drop"    ? &x.faults.drop_first_request_at
                         : kind == "stall" ? &x.faults.stall_at
                         : kind == "throw" ? &x.faults.throw_at
                         : kind == "crash" ? &x.faults.crash_at
                                           : nullptr;
    if (!slot || k.empty()) {
      std::fprintf(stderr, "rths run: --fault %s: expected ROLE:drop|stall|throw|crash:K\n", f.c_str());
      return rths::lockstep::kExitUsage;
    }
    *slot = std::stoll(k);
    faults.push_back(x);
  }

  rths::scenario::Scenario s;
  fs::path out;
  try {
    s = rths::scenario::LoadScenario(scenario_path);
    rths::participants::CheckBuildable(s);
    out = out_arg.empty() ? DefaultOutDir(s.run.name) : fs::path(out_arg);
    if (fs::exists(out) && !fs::is_empty(out)) {
      throw rths::Error(out.string(), "output folder exists and is not empty; refusing to overwrite "
                                      "a previous run (choose another --out)");
    }
    fs::create_directories(out);
    fs::copy_file(scenario_path, out / "scenario.toml");
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::lockstep::kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::lockstep::kExitUsage;
  }
  if (bin_dir.empty()) bin_dir = fs::read_symlink("/proc/self/exe").parent_path().string();

  std::random_device rd;
  const std::int64_t run_id =
      static_cast<std::int64_t>(((std::uint64_t{rd()} << 32) ^ rd()) & 0x3fffffffffffffffULL) | 1;
  std::string url = "memq://";
  std::vector<Outcome> outcomes;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    if (!quiet) {
      std::printf("rths run: %s (%lld steps of %g s), transport %s\n", scenario_path.c_str(),
                  static_cast<long long>(s.steps()), s.run.dt_s, transport.c_str());
      std::fflush(stdout);
    }
    outcomes = transport == "memq" ? rths::participants::RunGroupInProcess({s}, run_id, out.string(), faults)
                                   : RunUdpm(s, scenario_path, run_id, out, bin_dir, faults, &url);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::lockstep::kExitLockstep;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const Outcome* culprit = rths::participants::RootCause(outcomes);

  // Summary from the log: whatever was committed, even after a failure.
  nlohmann::json j;
  j["scenario"] = scenario_path;
  j["scenario_sha256"] = s.sha256;
  j["run_id"] = run_id;
  j["transport"] = transport;
  j["lcm_url"] = url;
  j["steps_expected"] = s.steps();
  j["wall_s"] = wall_s;
  std::int64_t steps = 0;
  try {
    const auto log = rths::io::ReadRunLog((out / "log.lcm").string());
    const auto m = rths::io::ComputeMetrics(log);
    steps = m.steps;
    j["steps"] = steps;
    j["steps_per_s"] = m.steps_per_s;
    j["tracking_nrmse_pct"] = m.tracking_nrmse_pct;
    j["peak_force_kN"] = m.peak_force_kN;
    j["peak_displacement_mm"] = m.peak_displacement_mm;
    j["accel_extrapolation_rms_err_pct"] = m.accel_extrapolation_rms_err_pct;
    j["velocity_prediction_rms_err_pct"] = m.velocity_prediction_rms_err_pct;
    std::int64_t dups = 0;
    for (const auto& [ch, n] : log.duplicates) dups += n;
    j["duplicates_logged"] = dups;
  } catch (const std::exception& e) {
    j["steps"] = 0;
    j["log_error"] = e.what();
  }
  j["stopped"] = g_interrupted ? std::string("interrupted by the user")
                 : culprit    ? fmt::format("{}: {}", culprit->role, culprit->message)
                              : std::string("no");
  j["participants"] = nlohmann::json::object();
  for (const auto& o : outcomes) j["participants"][o.role] = {{"exit_code", o.exit_code}, {"message", o.message}};
  std::ofstream(out / "summary.json") << j.dump(2) << "\n";

  if (!quiet) {
    std::printf("  steps              %lld of %lld\n", static_cast<long long>(steps),
                static_cast<long long>(s.steps()));
    if (j.contains("tracking_nrmse_pct")) {
      std::printf("  tracking error     %.3f %% (RMS, Eq. 31)\n", j["tracking_nrmse_pct"].get<double>());
      std::printf("  peak damper force  %.2f kN\n", j["peak_force_kN"].get<double>());
      std::printf("  rate               %.0f steps/s (%.2fx real time)\n", j["steps_per_s"].get<double>(),
                  j["steps_per_s"].get<double>() * s.run.dt_s);
    }
  }
  std::fflush(stdout);
  if (g_interrupted) {
    std::fprintf(stderr, "rths run: interrupted; the group was stopped\n");
    std::printf("output: %s (log valid up to step %lld)\n", out.string().c_str(),
                static_cast<long long>(steps));
    return 130;
  }
  if (culprit && culprit->exit_code == rths::lockstep::kExitSafety) {
    std::fprintf(stderr, "rths run: STOPPED by the safety monitor: %s\n", culprit->message.c_str());
    std::printf("output: %s (log valid up to step %lld)\n", out.string().c_str(),
                static_cast<long long>(steps));
    return rths::lockstep::kExitSafety;
  }
  if (culprit) {
    const char* what = culprit->signal ? strsignal(culprit->signal) : nullptr;
    std::fprintf(stderr, "rths run: FAILED: %s %s%s%s\n", culprit->role.c_str(),
                 what ? fmt::format("was killed by signal {} ({})", culprit->signal, what).c_str()
                      : fmt::format("exited with code {}", culprit->exit_code).c_str(),
                 culprit->message.empty() ? "" : ": ",
                 culprit->message.c_str());
    std::printf("output: %s (log valid up to step %lld)\n", out.string().c_str(),
                static_cast<long long>(steps));
    return culprit->exit_code != 0 ? culprit->exit_code : rths::lockstep::kExitLockstep;
  }
  std::printf("output: %s\n", out.string().c_str());
  return 0;
}
