// rths-run: the supervisor behind `rths run` (docs/lockstep.md).
//
// Validates the scenario, checks the host (multicast route, free disk space), makes the output
// folder, starts the five participants — as separate processes on udpm:// (one UDP port per
// run, ttl=0) or in this process on memq:// — and waits for them. A participant that dies is
// noticed at once (SIGCHLD through a signalfd): the supervisor broadcasts ABORT so the others
// stop cleanly, then terminates and kills whoever does not. At the end it writes summary.json
// (reserved before the run, so a full disk cannot take it) and exits non-zero naming the
// participant to blame.
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/progress.h"
#include "io/output_folder.h"
#include "io/reserved_file.h"
#include "io/run_log.h"
#include "lockstep/exit_code.h"
#include "lockstep/protocol.h"
#include "lockstep/realtime.h"
#include "lockstep/transport.h"
#include "models/structure_file.h"
#include "participants/factory.h"
#include "participants/group.h"
#include "participants/logger.h"
#include "participants/run_summary.h"
#include "report/run_report.h"
#include "scenario/scenario.h"
#include "cli.h"

namespace fs = std::filesystem;
using rths::participants::Outcome;
using Clock = std::chrono::steady_clock;

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = 1; }

/// Bytes reserved for summary.json before the run (written in place at the end).
constexpr std::size_t kSummaryReserve = 64 * 1024;
/// Runs that will write more than this get a warning first.
constexpr double kWarnBytes = 2e9;
/// After a failure: time the others get to stop by themselves after ABORT, then after SIGTERM.
constexpr auto kGraceAbort = std::chrono::milliseconds(1000);
constexpr auto kGraceTerm = std::chrono::milliseconds(1000);

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
  if (fd < 0) throw rths::Error("", "cannot create a UDP socket to pick a port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw rths::Error("", "cannot pick a free UDP port");
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

/// A base port P with P .. P+n-1 all free for UDP (each bound once, then released), picked by
/// the kernel's ephemeral allocator and checked.
int FreeUdpPorts(int n) {
  for (int attempt = 0; attempt < 64; ++attempt) {
    const int base = FreeUdpPort();
    if (base + n - 1 > 65535) continue;
    bool free = true;
    for (int i = 1; i < n && free; ++i) {
      const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
      if (fd < 0) throw rths::Error("", "cannot create a UDP socket to pick a port");
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_addr.s_addr = htonl(INADDR_ANY);
      a.sin_port = htons(static_cast<std::uint16_t>(base + i));
      free = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
      ::close(fd);
    }
    if (free) return base;
  }
  throw rths::Error("", fmt::format("cannot find {} consecutive free UDP ports", n));
}

std::string Megabytes(double bytes) { return fmt::format("{:.1f} MB", bytes / 1e6); }

int DegreesOfFreedom(const rths::scenario::Scenario& s) {
  if (s.structure.mode == rths::models::StructureMode::kPredefined) return 1;
  return static_cast<int>(rths::models::StructureFromScenario(s.structure, s.path).M.rows());
}

/// Output the run will write [bytes]: log.lcm, signals.csv, the reserved summary and some slack
/// for the copied scenario and the participants' own logs.
struct OutputEstimate {
  double log_bytes = 0.0, csv_bytes = 0.0, total_bytes = 0.0;
};
OutputEstimate EstimateOutput(const rths::scenario::Scenario& s) {
  const auto b = rths::participants::EstimateOutputBytes(s);
  return {b.log, b.csv, b.total() + static_cast<double>(kSummaryReserve) + 256.0 * 1024.0};
}

/// On a terminal: the run's progress (steps written, from the size of log.lcm) with an ETA,
/// redrawn four times a second until `stop`. Nothing when stderr is not a terminal.
class RunProgress {
 public:
  RunProgress(const fs::path& log, std::int64_t steps, std::int64_t log_bytes_per_step)
      : line_("rths run") {
    if (!line_.enabled() || steps <= 0) return;
    thread_ = std::thread([this, log, steps, log_bytes_per_step] {
      std::unique_lock<std::mutex> lock(mutex_);
      bool drawn = false;
      while (!stop_) {
        std::error_code ec;
        const auto bytes = fs::file_size(log, ec);
        if (!ec) {
          drawn = true;
          const double done = std::min<double>(static_cast<double>(bytes) / static_cast<double>(log_bytes_per_step),
                                               static_cast<double>(steps));
          line_.Update(done, static_cast<double>(steps),
                       fmt::format("step {} of {}", static_cast<long long>(done), static_cast<long long>(steps)));
        }
        // Until log.lcm exists (the participants are starting), look again soon: a short run
        // shows its line too.
        cv_.wait_for(lock, std::chrono::milliseconds(drawn ? 250 : 20));
      }
    });
  }
  ~RunProgress() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    line_.Finish();
  }

 private:
  rths::ProgressLine line_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
};

/// Free bytes for an unprivileged writer on the file system that will hold `dir`.
double FreeBytes(fs::path dir) {
  dir = fs::absolute(dir);
  while (!fs::exists(dir) && dir.has_parent_path() && dir != dir.parent_path()) dir = dir.parent_path();
  struct statvfs st {};
  if (::statvfs(dir.c_str(), &st) != 0) return -1.0;
  return static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
}

/// The state letter of /proc/PID/stat ('T': stopped), or 0.
char ProcessState(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = all.rfind(')');
  return close != std::string::npos && close + 2 < all.size() ? all[close + 2] : 0;
}

/// Tells every participant of the run to stop: ABORT on the run's URL, from "supervisor".
void BroadcastAbort(const std::string& url, std::int64_t run_id, const std::string& reason) {
  // A run with a port per channel hears handshakes on the handshake channel's port.
  const auto parsed = rths::lockstep::UdpmUrl::Parse(url);
  lcm::LCM lcm(parsed ? parsed->ChannelUrl(rths::lockstep::kChHandshake) : url);
  if (!lcm.good()) return;
  rths::handshake_t h{};
  h.run_id = run_id;
  h.phase = rths::lockstep::kAbort;
  h.participant = "supervisor";
  h.k = -1;
  h.n_roster = 0;
  h.reason = reason;
  rths::lockstep::Bytes bytes;
  rths::lockstep::Encode(h, &bytes);
  for (int i = 0; i < 3; ++i) lcm.publish(rths::lockstep::kChHandshake, bytes.data(), bytes.size());
}

struct Child {
  Outcome outcome;
  bool exited = false;
  bool signalled_by_us = false;
};

/// What `--external` changes: the roles the user runs, and how long everyone waits for them.
struct ExternalRoles {
  std::vector<std::string> roles;
  double join_timeout_s = 0;  ///< 0: the scenario's lockstep.handshake_timeout_s
  bool has(const std::string& role) const {
    return std::find(roles.begin(), roles.end(), role) != roles.end();
  }
};

std::vector<Outcome> RunUdpm(const std::string& scenario_path, const rths::scenario::Scenario& /*s*/,
                             std::int64_t run_id, const fs::path& out, const fs::path& bin_dir,
                             const std::string& url, const ExternalRoles& external,
                             const std::vector<std::string>& role_args, Clock::time_point* noticed) {
  fs::create_directories(out / "logs");
  // SIGCHLD, SIGINT and SIGTERM arrive through a signalfd: a dead participant is noticed at once.
  sigset_t mask, old_mask;
  sigemptyset(&mask);
  sigaddset(&mask, SIGCHLD);
  sigaddset(&mask, SIGINT);
  sigaddset(&mask, SIGTERM);
  if (::sigprocmask(SIG_BLOCK, &mask, &old_mask) != 0) throw rths::Error("", "cannot block signals");
  const int sfd = ::signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK);
  if (sfd < 0) throw rths::Error("", "cannot create a signalfd");

  std::map<pid_t, Child> children;
  for (const char* role : {"logger", "plant", "controller", "semiactive", "integrator"}) {
    if (external.has(role)) continue;
    const fs::path exe = bin_dir / fmt::format("rths-{}", role);
    if (!fs::exists(exe)) throw rths::Error("", fmt::format("{} is missing: build first (see README)", exe.string()));
    std::vector<std::string> args{exe.string(), "--scenario", scenario_path,        "--lcm-url", url,
                                  "--run-id",   std::to_string(run_id), "--out", out.string()};
    args.insert(args.end(), role_args.begin(), role_args.end());
    if (external.join_timeout_s > 0) {
      args.insert(args.end(), {"--handshake-timeout-s", fmt::format("{}", external.join_timeout_s)});
    }
    const fs::path log = out / "logs" / fmt::format("{}.log", role);
    const pid_t pid = ::fork();
    if (pid < 0) throw rths::Error("", "fork failed");
    if (pid == 0) {
      ::sigprocmask(SIG_SETMASK, &old_mask, nullptr);
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
    children[pid].outcome.role = role;
  }

  std::size_t running = children.size();
  bool tearing_down = false, termed = false, killed = false;
  Clock::time_point term_at{}, kill_at{};
  auto start_teardown = [&](const std::string& reason) {
    if (tearing_down) return;
    tearing_down = true;
    *noticed = Clock::now();
    BroadcastAbort(url, run_id, reason);
    term_at = *noticed + kGraceAbort;
  };
  auto signal_survivors = [&](int sig) {
    for (auto& [pid, c] : children) {
      if (c.exited) continue;
      if (ProcessState(pid) == 'T') c.outcome.was_stopped = true;
      c.signalled_by_us = true;
      ::kill(pid, sig);
    }
  };
  while (running > 0) {
    int timeout_ms = 200;
    const auto now = Clock::now();
    if (tearing_down && !termed) timeout_ms = static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(term_at - now).count());
    if (termed && !killed) timeout_ms = static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(kill_at - now).count());
    pollfd p{sfd, POLLIN, 0};
    const int r = ::poll(&p, 1, std::max(timeout_ms, 0));
    if (r > 0) {
      signalfd_siginfo si{};
      while (::read(sfd, &si, sizeof si) == sizeof si) {
        if (si.ssi_signo == SIGINT || si.ssi_signo == SIGTERM) {
          g_interrupted = 1;
          start_teardown("interrupted by the user");
        }
      }
      // Reap everyone who has exited (one SIGCHLD may stand for several).
      for (;;) {
        int status = 0;
        const pid_t pid = ::waitpid(-1, &status, WNOHANG);
        if (pid <= 0) break;
        auto it = children.find(pid);
        if (it == children.end()) continue;
        Child& c = it->second;
        c.exited = true;
        --running;
        Outcome& o = c.outcome;
        if (WIFSIGNALED(status)) {
          o.signal = WTERMSIG(status);
          o.exit_code = 128 + o.signal;
          o.killed_by_supervisor = c.signalled_by_us;
        } else {
          o.exit_code = WEXITSTATUS(status);
        }
        if (o.exit_code != 0) {
          const std::string what =
              o.signal ? fmt::format("{} was killed by signal {} ({})", o.role, o.signal, strsignal(o.signal))
                       : fmt::format("{} exited with code {}", o.role, o.exit_code);
          start_teardown(what);
        }
      }
    }
    const auto t = Clock::now();
    if (tearing_down && !termed && t >= term_at) {
      signal_survivors(SIGTERM);
      termed = true;
      kill_at = t + kGraceTerm;
    }
    if (termed && !killed && t >= kill_at) {
      signal_survivors(SIGKILL);
      killed = true;
    }
  }
  ::close(sfd);
  ::sigprocmask(SIG_SETMASK, &old_mask, nullptr);

  // What each participant wrote about itself (its message, whom it blames, its link counters).
  std::vector<Outcome> outcomes;
  for (auto& [pid, c] : children) {
    Outcome o = c.outcome;
    try {
      std::ifstream in(out / "logs" / (o.role + ".json"));
      if (in) {
        Outcome self = rths::participants::OutcomeFromJson(nlohmann::json::parse(in));
        o.message = self.message;
        o.culprit = self.culprit;
        o.step = self.step;
        o.stats = self.stats;
        o.stats_known = self.stats_known;
        o.stepping_s = self.stepping_s;
        o.realtime_setup = self.realtime_setup;
        o.realtime_json = self.realtime_json;
      }
    } catch (const std::exception&) {
      // a partial file (the disk filled up): keep what the exit status says
    }
    if (o.exit_code != 0 && o.message.empty() && !o.signal) o.message = LastLine(out / "logs" / (o.role + ".log"));
    outcomes.push_back(std::move(o));
  }
  for (const auto& role : external.roles) {
    Outcome o;
    o.role = role;
    o.external = true;
    outcomes.push_back(std::move(o));
  }
  return outcomes;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths run: start a lockstep RTHS run (integrator, controller, plant, semiactive, "
               "logger), wait for it, and write its output folder"};
  std::string scenario_path, default_scenario = "scenarios/default.toml";
  std::string out_arg, transport = "udpm", bin_dir;
  bool quiet = false, skip_space_check = false;
  app.add_option("scenario", scenario_path, "scenario TOML file (default: scenarios/default.toml)");
  app.add_option("--default-scenario", default_scenario, "used when no scenario is given")->group("");
  app.add_option("--out", out_arg, "output folder (default: a new folder under runs/)");
  app.add_option("--transport", transport, "udpm: one process per participant; memq: one process")
      ->check(CLI::IsMember({"udpm", "memq"}))
      ->capture_default_str();
  app.add_option("--bin-dir", bin_dir, "where the rths-* programs are (default: next to this one)");
  app.add_flag("--quiet", quiet, "print only the output folder");
  std::string url_arg, external_arg;
  std::int64_t run_id_arg = 0;
  double join_timeout_s = 120.0;
  app.add_option("--lcm-url", url_arg,
                 "udpm URL of the run (default: udpm://239.255.76.67:<a free port>?ttl=0); ttl=1 to reach "
                 "participants on other hosts of the LAN (docs/participant.md)");
  bool port_per_channel = false;
  app.add_flag("--port-per-channel", port_per_channel,
               "udpm: carry each channel on its own UDP port (the run's port + 0..6), so each process "
               "receives only the channels it reads: fewer deliveries per step, a faster run; the same "
               "payloads (as --lcm-url 'udpm://239.255.76.67:PORT?ttl=0&port_per_channel=1'; "
               "docs/lockstep.md, Transports)");
  app.add_option("--run-id", run_id_arg, "run id every participant must use (default: random)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{0x3fffffffffffffff}));
  app.add_option("--external", external_arg,
                 "ROLE[,ROLE...]: do not start these participants (controller, plant, semiactive); wait "
                 "for the user's own to join the handshake (docs/participant.md)");
  bool realtime = false;
  app.add_flag("--realtime", realtime,
               "pace the run to the wall clock at the scenario's dt (as [realtime] enabled = true): "
               "latency percentiles and deadline misses in summary.json (docs/realtime.md)");
  app.add_option("--join-timeout-s", join_timeout_s,
                 "with --external: how long to wait for the external participants to say HELLO [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_flag("--skip-space-check", skip_space_check, "tests only: do not check the free disk space first")
      ->group("");
  app.footer("Exit codes: 0 ok; 2 bad input or not enough disk (nothing ran); 3 a participant stopped "
             "answering (named); 4 stopped by an abort; 5 a participant's computation failed; 6 stopped "
             "by the safety monitor; 7 the output could not be written (disk full); 8 real-time mode: too many "
             "consecutive deadline misses; 128+N a participant was killed by signal N; 130 interrupted.");
  std::vector<std::string> sets;
  rths::tools::AddSetOption(app, &sets);
  bool compact = false;
  app.add_flag("--compact", compact,
               "no signals.csv (as --set run.csv_every=0): log.lcm alone holds every step; `rths export` makes "
               "a CSV or .mat of it when needed");
  bool report = false;
  app.add_flag("--report", report, "at the end, write RUN_DIR/report.html with figures (as `rths report RUN_DIR`)");
  rths::tools::NameCommand(app, "run");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;

  if (scenario_path.empty()) scenario_path = default_scenario;
  if (compact) sets.push_back("run.csv_every=0");
  std::string shown_scenario = scenario_path;  // as the user named it, with the overrides
  for (const auto& set : sets) shown_scenario += " --set " + set;
  ExternalRoles external;
  {
    std::stringstream ss(external_arg);
    for (std::string role; std::getline(ss, role, ',');) {
      if (role.empty()) continue;
      if (role == "integrator" || role == "logger") {
        std::fprintf(stderr,
                     "rths run: --external %s: the %s cannot be external (%s); allowed: controller, plant, "
                     "semiactive\n",
                     role.c_str(), role.c_str(),
                     role == "integrator" ? "it is the run's clock" : "the run's record must be written by rths");
        return rths::lockstep::kExitUsage;
      }
      if (role != "controller" && role != "plant" && role != "semiactive") {
        std::fprintf(stderr, "rths run: --external %s: unknown role; allowed: controller, plant, semiactive\n",
                     role.c_str());
        return rths::lockstep::kExitUsage;
      }
      if (!external.has(role)) external.roles.push_back(role);
    }
    if (!external.roles.empty()) {
      if (transport != "udpm") {
        std::fprintf(stderr, "rths run: --external needs the udpm transport (an external process cannot join "
                             "memq, which lives inside one process)\n");
        return rths::lockstep::kExitUsage;
      }
      external.join_timeout_s = join_timeout_s;
    }
    if (!url_arg.empty() && transport != "udpm") {
      std::fprintf(stderr, "rths run: --lcm-url needs the udpm transport\n");
      return rths::lockstep::kExitUsage;
    }
    if (!url_arg.empty() && url_arg.rfind("udpm://", 0) != 0) {
      std::fprintf(stderr, "rths run: --lcm-url %s: must be a udpm:// URL (e.g. udpm://239.255.76.67:7667?ttl=0)\n",
                   url_arg.c_str());
      return rths::lockstep::kExitUsage;
    }
    if (port_per_channel && transport != "udpm") {
      std::fprintf(stderr, "rths run: --port-per-channel needs the udpm transport\n");
      return rths::lockstep::kExitUsage;
    }
    if (!url_arg.empty()) {
      std::string why;
      auto parsed = rths::lockstep::UdpmUrl::Parse(url_arg, &why);
      if (!parsed) {
        std::fprintf(stderr, "rths run: --lcm-url %s\n", why.c_str());
        return rths::lockstep::kExitUsage;
      }
      if (port_per_channel && !parsed->port_per_channel) {
        parsed->port_per_channel = true;
        url_arg = parsed->ToString();
      }
    }
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  // Everything that can be checked before a byte is written.
  rths::scenario::Scenario s;
  fs::path out;
  double estimate = 0.0;
  OutputEstimate sizes;
  std::string url = "memq://";
  try {
    s = rths::scenario::LoadScenario(scenario_path, sets);
    if (realtime) s.realtime.enabled = true;
    rths::participants::CheckBuildable(s);
    const rths::lockstep::ProcessFault kind = s.faults.process_kind;
    if (transport == "memq" && rths::lockstep::EndsProcess(kind)) {
      throw rths::Error(scenario_path + ": faults.process.kind",
                        fmt::format("\"{}\" would take every participant down with the one memq process: "
                                    "use --transport udpm",
                                    rths::NameOf(rths::lockstep::kProcessFaultNames, kind)));
    }
    if (transport == "udpm") {
      if (const std::string hint = rths::lockstep::CheckMulticastRoute(); !hint.empty()) {
        throw rths::Error("", hint);
      }
      url = !url_arg.empty()     ? url_arg
            : port_per_channel ? fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1",
                                             FreeUdpPorts(static_cast<int>(rths::lockstep::kPortChannels.size())))
                               : fmt::format("udpm://239.255.76.67:{}?ttl=0", FreeUdpPort());
      if (s.faults.recv_buf_bytes > 0) {
        url += fmt::format("{}recv_buf_size={}", url.find('?') == std::string::npos ? "?" : "&",
                           s.faults.recv_buf_bytes);
      }
    }
    out = out_arg.empty() ? rths::io::NewOutputFolder(s.run.name) : fs::path(out_arg);
    rths::io::RequireNewOrEmptyFolder(out, "a previous run");
    sizes = EstimateOutput(s);
    estimate = sizes.total_bytes;
    const double free_bytes = FreeBytes(out);
    if (!skip_space_check && free_bytes >= 0 && estimate > free_bytes) {
      throw rths::Error(out.string(),
                        fmt::format("not enough free disk space: this run writes about {} ({} steps), and "
                                    "the file system has {} free; free some space, shorten run.duration_s "
                                    "or choose another --out",
                                    Megabytes(estimate), s.steps(), Megabytes(free_bytes)));
    }
    if (estimate > kWarnBytes) {
      std::fprintf(stderr, "rths run: warning: this run will write about %s to %s\n", Megabytes(estimate).c_str(),
                   out.string().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::lockstep::kExitUsage;
  }

  // The output folder; if nothing could start, remove what was made here so a retry with the
  // same --out works.
  const bool created_out = !fs::exists(out);
  try {
    fs::create_directories(out);
    if (sets.empty()) {
      fs::copy_file(scenario_path, out / "scenario.toml");
    } else {
      // The scenario that runs is the file with the overrides: written out in full (file paths
      // absolute), loaded back so its hash is the file's, and given to every participant.
      std::string header = fmt::format("# {} with", scenario_path);
      for (const auto& set : sets) header += " --set " + set;
      const fs::path effective = out / "scenario.toml";
      std::ofstream file(effective, std::ios::binary);
      if (!(file << header << "\n" << rths::scenario::ToToml(s)) || !file.flush()) {
        throw rths::Error(effective.string(), "cannot write the scenario (disk full?)");
      }
      file.close();
      const bool paced = s.realtime.enabled;
      s = rths::scenario::LoadScenario(effective.string());
      s.realtime.enabled = paced;
      scenario_path = effective.string();
    }
    if (!rths::io::ReserveFile((out / "summary.json").string(), kSummaryReserve, "{\"status\": \"running\"}\n")) {
      throw rths::Error((out / "summary.json").string(), "cannot reserve the summary (disk full?)");
    }
  } catch (const std::exception& e) {
    std::error_code ec;
    if (created_out) fs::remove_all(out, ec);
    std::fprintf(stderr, "rths run: %s\n", e.what());
    return rths::lockstep::kExitUsage;
  }
  if (bin_dir.empty()) bin_dir = fs::read_symlink("/proc/self/exe").parent_path().string();

  const std::int64_t run_id = run_id_arg > 0 ? run_id_arg : rths::lockstep::NewRunId();
  std::vector<Outcome> outcomes;
  rths::lockstep::RealtimeSetup memq_setup;
  const auto t0 = Clock::now();
  Clock::time_point noticed{};
  try {
    if (!quiet) {
      std::printf("rths run: %s (%lld steps of %g s), transport %s\n", shown_scenario.c_str(),
                  static_cast<long long>(s.steps()), s.run.dt_s, transport.c_str());
      // log.lcm's size is exact; a CSV row's length depends on the numbers (%.17g), so its size is
      // a bound (a 20 s default run: 6.5 MB written of 11.8 MB at most).
      if (s.run.csv_every == 0) {
        std::printf("  output           %s: log.lcm %s, no signals.csv (run.csv_every = 0, as --compact)\n",
                    Megabytes(sizes.total_bytes).c_str(), Megabytes(sizes.log_bytes).c_str());
      } else {
        std::printf("  output           at most %s: log.lcm %s, signals.csv up to %s%s\n",
                    Megabytes(sizes.total_bytes).c_str(), Megabytes(sizes.log_bytes).c_str(),
                    Megabytes(sizes.csv_bytes).c_str(),
                    s.run.csv_every == 1 ? " (--compact: none)"
                                         : fmt::format(" (every {} steps)", s.run.csv_every).c_str());
      }
      std::fflush(stdout);
    }
    const RunProgress progress(out / "log.lcm", s.steps(), rths::participants::LogBytesPerStep(DegreesOfFreedom(s)));
    if (!external.roles.empty()) {
      // Always printed (also with --quiet): what the user's participants need to join.
      std::string roles;
      for (const auto& r : external.roles) roles += (roles.empty() ? "" : ",") + r;
      std::printf("external: %s\n", roles.c_str());
      std::printf("  lcm_url          %s\n", url.c_str());
      std::printf("  port             %s\n", url.substr(url.rfind(':') + 1, url.find('?') - url.rfind(':') - 1).c_str());
      std::printf("  run_id           %lld\n", static_cast<long long>(run_id));
      std::printf("  scenario         %s\n", scenario_path.c_str());
      std::printf("  scenario_sha256  %s\n", s.sha256.c_str());
      std::printf("  steps            %lld of %g s each\n", static_cast<long long>(s.steps()), s.run.dt_s);
      std::printf("  built-in example %s/rths-%s --scenario %s --lcm-url '%s' --run-id %lld\n",
                  bin_dir.c_str(), external.roles.front().c_str(), scenario_path.c_str(), url.c_str(),
                  static_cast<long long>(run_id));
      std::printf("waiting up to %g s for %s to say HELLO (docs/participant.md)\n", external.join_timeout_s,
                  roles.c_str());
      std::fflush(stdout);
    }
    std::vector<std::string> role_args;
    if (realtime) role_args.push_back("--realtime");
    if (transport == "memq") {
      if (s.realtime.enabled) {
        // Every participant runs on this thread: the set-up is this process's.
        memq_setup = rths::lockstep::EnterRealtime(s.realtime.sched_fifo, s.realtime.priority, s.realtime.lock_memory);
      }
      outcomes = rths::participants::RunGroupInProcess({s}, run_id, out.string(), {}, &g_interrupted);
    } else {
      outcomes = RunUdpm(scenario_path, s, run_id, out, bin_dir, url, external, role_args, &noticed);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths run: %s\n", e.what());
    std::error_code ec;
    if (created_out && !fs::exists(out / "log.lcm")) fs::remove_all(out, ec);
    return rths::lockstep::kExitLockstep;
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  rths::participants::Verdict verdict = rths::participants::Judge(outcomes);

  // Summary from the log: whatever was committed, even after a failure.
  rths::participants::RunSummary sum;
  sum.scenario = scenario_path;
  sum.scenario_sha256 = s.sha256;
  sum.run_id = run_id;
  sum.transport = transport;
  sum.lcm_url = url;
  sum.steps_expected = s.steps();
  sum.wall_s = wall_s;
  sum.output_estimate_bytes = estimate;
  rths::participants::ReadLog((out / "log.lcm").string(), s, &sum);  // + J1-J9 with a reference_file
  rths::participants::SetOutcomes(outcomes, &sum);
  rths::participants::SetVerdict(verdict, g_interrupted != 0, &sum);
  if (sum.failure && noticed != Clock::time_point{}) {
    sum.failure->teardown_s = std::chrono::duration<double>(Clock::now() - noticed).count();
  }
  // Paced runs: the clock's latency figures, and what each process got of SCHED_FIFO / mlockall.
  if (s.realtime.enabled) {
    nlohmann::json rt;
    for (const auto& o : outcomes) {
      if (const nlohmann::json r = o.RealtimeJson(); !r.is_null()) rt = r;
    }
    if (rt.is_null()) rt = nlohmann::json::object();
    int fifo = 0, locked = 0, processes = 0;
    std::string notes;
    auto count = [&](const rths::lockstep::RealtimeSetup& r, const std::string& who) {
      if (!r.tried) return;
      ++processes;
      fifo += r.fifo;
      locked += r.memory_locked;
      if (!r.note.empty() && notes.find(r.note) == std::string::npos) notes += (notes.empty() ? "" : "; ") + who + ": " + r.note;
    };
    if (transport == "memq") {
      count(memq_setup, "rths run (memq: every participant)");
    } else {
      for (const auto& o : outcomes) count(o.realtime_setup, o.role);
    }
    rt["processes"] = processes;
    rt["sched_fifo_processes"] = fifo;
    rt["memory_locked_processes"] = locked;
    rt["priority"] = s.realtime.priority;
    rt["setup_notes"] = notes;
    rt["max_consecutive_misses_policy"] = s.realtime.max_consecutive_misses;
    sum.realtime = rt;
  }
  const bool summary_ok = rths::io::OverwriteFile((out / "summary.json").string(), sum.ToJson().dump(2) + "\n");
  if (!quiet) std::fputs(sum.Report(s.run.dt_s).c_str(), stdout);
  std::fflush(stdout);
  if (!summary_ok) std::fprintf(stderr, "rths run: could not write %s\n", (out / "summary.json").c_str());
  const int code = sum.exit_code;
  const std::string what = sum.failure ? sum.failure->what : "";
  const std::int64_t steps = sum.steps;
  if (report && steps > 0) {
    // The report of what was logged (also of a run that stopped: its complete steps). A report
    // that cannot be made is a warning; the run's exit code stays the run's.
    try {
      const auto files = rths::report::WriteRunReport(out);
      std::printf("report: %s (%zu figures)\n", files.html.string().c_str(), files.figures.size());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rths run: warning: no report: %s\n", e.what());
    }
  }
  if (code == 0) {
    std::printf("output: %s\n", out.string().c_str());
    return 0;
  }
  if (g_interrupted) {
    std::fprintf(stderr, "rths run: interrupted; the group was stopped\n");
  } else if (code == rths::lockstep::kExitSafety) {
    std::fprintf(stderr, "rths run: STOPPED by the safety monitor: %s\n", what.c_str());
  } else if (code == rths::lockstep::kExitRealtime) {
    std::fprintf(stderr, "rths run: STOPPED by the real-time miss policy: %s\n", what.c_str());
  } else {
    std::fprintf(stderr, "rths run: FAILED: %s\n", what.c_str());
  }
  if (steps > 0) {
    std::printf("output: %s (log complete up to step %lld)\n", out.string().c_str(), static_cast<long long>(steps) - 1);
  } else {
    std::printf("output: %s (no step completed)\n", out.string().c_str());
  }
  return code;
}
