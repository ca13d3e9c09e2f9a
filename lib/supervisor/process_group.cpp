#include "supervisor/process_group.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "lockstep/step_table.h"

namespace rths::supervisor {

namespace fs = std::filesystem;
using participants::Outcome;

namespace {

struct Child {
  Outcome outcome;
  bool exited = false;
  bool signalled_by_us = false;
};
using Children = std::map<pid_t, Child>;

/// SIGCHLD, SIGINT and SIGTERM blocked and readable from a signalfd while it lives.
class SignalWatch {
 public:
  SignalWatch() {
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGCHLD);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    if (::sigprocmask(SIG_BLOCK, &mask, &old_mask_) != 0) throw Error("", "cannot block signals");
    fd_ = ::signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK);
    if (fd_ < 0) throw Error("", "cannot create a signalfd");
  }
  ~SignalWatch() {
    ::close(fd_);
    ::sigprocmask(SIG_SETMASK, &old_mask_, nullptr);
  }
  SignalWatch(const SignalWatch&) = delete;
  SignalWatch& operator=(const SignalWatch&) = delete;
  int fd() const { return fd_; }
  const sigset_t& old_mask() const { return old_mask_; }

 private:
  sigset_t old_mask_{};
  int fd_ = -1;
};

/// Forks and execs `args` with stdout and stderr to `log`; the child dies with its parent.
pid_t Spawn(std::vector<std::string> args, const fs::path& log, const sigset_t& old_mask) {
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("", "fork failed");
  if (pid > 0) return pid;
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

/// Starts every participant the user does not run, in lockstep::kBuildOrder.
Children StartAll(const ProcessGroupSpec& spec, const sigset_t& old_mask) {
  Children children;
  for (const std::string_view role_view : lockstep::kBuildOrder) {
    const std::string role(role_view);
    if (spec.external.has(role)) continue;
    const fs::path exe = spec.bin_dir / fmt::format("rths-{}", role);
    if (!fs::exists(exe)) throw Error("", fmt::format("{} is missing: build first (see README)", exe.string()));
    std::vector<std::string> args{exe.string(), "--scenario", spec.scenario_path,         "--lcm-url", spec.url,
                                  "--run-id",   std::to_string(spec.run_id), "--out", spec.out.string()};
    args.insert(args.end(), spec.role_args.begin(), spec.role_args.end());
    if (spec.external.join_timeout_s > 0) {
      args.insert(args.end(), {"--handshake-timeout-s", fmt::format("{}", spec.external.join_timeout_s)});
    }
    const pid_t pid = Spawn(std::move(args), spec.out / "logs" / fmt::format("{}.log", role), old_mask);
    children[pid].outcome.role = role;
  }
  return children;
}

/// Records how `c` ended from its wait status; returns why the group must stop ("" if it ended well).
std::string Ended(Child* c, int status) {
  c->exited = true;
  Outcome& o = c->outcome;
  if (WIFSIGNALED(status)) {
    o.signal = WTERMSIG(status);
    o.exit_code = 128 + o.signal;
    o.killed_by_supervisor = c->signalled_by_us;
  } else {
    o.exit_code = WEXITSTATUS(status);
  }
  if (o.exit_code == 0) return "";
  return o.signal ? fmt::format("{} was killed by signal {} ({})", o.role, o.signal, strsignal(o.signal))
                  : fmt::format("{} exited with code {}", o.role, o.exit_code);
}

/// Sends `sig` to every child still running (noting one that was stopped, state T).
void SignalSurvivors(Children* children, int sig) {
  for (auto& [pid, c] : *children) {
    if (c.exited) continue;
    if (ProcessState(pid) == 'T') c.outcome.was_stopped = true;
    c.signalled_by_us = true;
    ::kill(pid, sig);
  }
}

/// Waits until every child has exited, tearing the group down after the first failure or an
/// interrupt.
void WaitAll(Children* children, const SignalWatch& watch, Teardown* teardown, volatile std::sig_atomic_t* interrupted) {
  std::size_t running = children->size();
  while (running > 0) {
    pollfd p{watch.fd(), POLLIN, 0};
    if (::poll(&p, 1, teardown->WaitMs(200)) > 0) {
      signalfd_siginfo si{};
      while (::read(watch.fd(), &si, sizeof si) == sizeof si) {
        if (si.ssi_signo == SIGINT || si.ssi_signo == SIGTERM) {
          if (interrupted) *interrupted = 1;
          teardown->Start("interrupted by the user");
        }
      }
      // Reap everyone who has exited (one SIGCHLD may stand for several).
      for (;;) {
        int status = 0;
        const pid_t pid = ::waitpid(-1, &status, WNOHANG);
        if (pid <= 0) break;
        auto it = children->find(pid);
        if (it == children->end()) continue;
        --running;
        if (const std::string why = Ended(&it->second, status); !why.empty()) teardown->Start(why);
      }
    }
    if (const int sig = teardown->Due()) SignalSurvivors(children, sig);
  }
}

std::string LastLine(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

/// `c`'s outcome with what the participant wrote about itself (its message, whom it blames, its
/// link counters) from out/logs/<role>.json.
Outcome WithSelfReport(Outcome o, const fs::path& out) {
  try {
    std::ifstream in(out / "logs" / (o.role + ".json"));
    if (in) {
      const Outcome self = participants::OutcomeFromJson(nlohmann::json::parse(in));
      o.message = self.message;
      o.culprit = self.culprit;
      o.step = self.step;
      o.stats = self.stats;
      o.stats_known = self.stats_known;
      o.stepping_s = self.stepping_s;
      o.output_stalls = self.output_stalls;
      o.realtime_setup = self.realtime_setup;
      o.realtime_json = self.realtime_json;
      o.peers = self.peers;
    }
  } catch (const std::exception&) {
    // a partial file (the disk filled up): keep what the exit status says
  }
  if (o.exit_code != 0 && o.message.empty() && !o.signal) o.message = LastLine(out / "logs" / (o.role + ".log"));
  return o;
}

}  // namespace

std::vector<Outcome> RunProcessGroup(const ProcessGroupSpec& spec, volatile std::sig_atomic_t* interrupted,
                                     Clock::time_point* noticed) {
  fs::create_directories(spec.out / "logs");
  Children children;
  Teardown teardown(spec.url, spec.run_id);
  {
    const SignalWatch watch;  // a dead participant is noticed at once
    children = StartAll(spec, watch.old_mask());
    WaitAll(&children, watch, &teardown, interrupted);
  }
  if (teardown.started()) *noticed = teardown.noticed();
  std::vector<Outcome> outcomes;
  for (auto& [pid, c] : children) outcomes.push_back(WithSelfReport(c.outcome, spec.out));
  return outcomes;
}

}  // namespace rths::supervisor
