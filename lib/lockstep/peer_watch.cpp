#include "lockstep/peer_watch.h"

#include <linux/cn_proc.h>
#include <linux/connector.h>
#include <linux/netlink.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

namespace rths::lockstep {

namespace {

double Seconds(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

int PidfdOpen(pid_t pid) { return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0)); }

/// The wait status in /proc/PID/stat (field 52) while the process is a zombie not yet reaped by
/// its parent; -1 if it is gone or unreadable.
int ZombieStatus(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string line;
  if (!std::getline(in, line)) return -1;
  const std::size_t close = line.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return -1;
  std::istringstream fields(line.substr(close + 2));
  std::string f;
  std::string state;
  fields >> state;
  if (state != "Z") return -1;
  // Fields 4..52 follow the state (field 3); the exit code is field 52.
  for (int i = 4; i <= 52; ++i) {
    if (!(fields >> f)) return -1;
  }
  try {
    return std::stoi(f);
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace

PeerWatch::~PeerWatch() {
  for (Peer& p : peers_) {
    if (p.pidfd >= 0) ::close(p.pidfd);
  }
  if (events_fd_ >= 0) ::close(events_fd_);
}

void PeerWatch::Watch(int role, std::int32_t pid, double heartbeat_s, SteadyClock::time_point now) {
  if (role < 0 || role >= kRosterSize) return;
  Peer& p = peers_[role];
  if (p.pidfd >= 0) ::close(p.pidfd);
  p = Peer{};
  p.pid = pid;
  p.heartbeat_s = heartbeat_s > 0 ? heartbeat_s : 0;
  p.last_beat = now;
  exit_status_[role] = -1;
  if (pid > 0 && pid != ::getpid()) {
    OpenExitEvents();  // before it can die unseen
    p.pidfd = PidfdOpen(pid);
  }
}

void PeerWatch::Beat(int role, SteadyClock::time_point now) {
  if (role >= 0 && role < kRosterSize) peers_[role].last_beat = now;
}

void PeerWatch::Forget(int role) {
  if (role < 0 || role >= kRosterSize) return;
  if (peers_[role].pidfd >= 0) ::close(peers_[role].pidfd);
  peers_[role].pidfd = -1;
  peers_[role].heartbeat_s = 0;
}

SteadyClock::time_point PeerWatch::NextCheck() const {
  for (const Peer& p : peers_) {
    if (p.pidfd >= 0 || p.heartbeat_s > 0) return next_check_;
  }
  return SteadyClock::time_point::max();
}

std::optional<PeerLoss> PeerWatch::Check(SteadyClock::time_point now) {
  if (now < next_check_) return std::nullopt;
  next_check_ = now + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(kCheckPeriodS));
  DrainExitEvents();  // keep the socket's queue short: a full queue drops the events we want
  for (int i = 0; i < kRosterSize; ++i) {
    Peer& p = peers_[i];
    if (p.pidfd >= 0) {
      pollfd fd{p.pidfd, POLLIN, 0};
      if (::poll(&fd, 1, 0) > 0) return Died(i);
    }
    if (p.heartbeat_s > 0 && Seconds(p.last_beat, now) > kMissedBeats * p.heartbeat_s) {
      PeerLoss loss;
      loss.role = i;
      loss.silent_s = Seconds(p.last_beat, now);
      loss.what = fmt::format("no HEARTBEAT for {:.3g} s ({} periods of {:g} s declared in its HELLO)", loss.silent_s,
                              kMissedBeats, p.heartbeat_s);
      p.heartbeat_s = 0;
      return loss;
    }
  }
  return std::nullopt;
}

PeerLoss PeerWatch::Died(int role) {
  Peer& p = peers_[role];
  ::close(p.pidfd);
  p.pidfd = -1;
  p.heartbeat_s = 0;
  PeerLoss loss;
  loss.role = role;
  loss.died = true;
  int status = ZombieStatus(p.pid);
  if (status < 0) {
    DrainExitEvents();
    status = exit_status_[role];
  }
  if (status >= 0) {
    loss.status_known = true;
    if (WIFSIGNALED(status)) {
      loss.signal = WTERMSIG(status);
      loss.what = fmt::format("its process (pid {}) was killed by signal {} ({})", p.pid, loss.signal,
                              ::strsignal(loss.signal));
    } else {
      loss.exit_code = WEXITSTATUS(status);
      loss.what = fmt::format("its process (pid {}) exited with code {} before the run ended", p.pid, loss.exit_code);
    }
  } else {
    loss.what = fmt::format("its process (pid {}) ended; its exit status is not visible here (not a child of "
                            "rths, and reading the kernel's process events needs CAP_NET_ADMIN)",
                            p.pid);
  }
  return loss;
}

bool PeerWatch::OpenExitEvents() {
  if (events_tried_) return events_fd_ >= 0;
  events_tried_ = true;
  const int fd = ::socket(PF_NETLINK, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, NETLINK_CONNECTOR);
  if (fd < 0) return false;
  sockaddr_nl addr{};
  addr.nl_family = AF_NETLINK;
  addr.nl_groups = CN_IDX_PROC;
  addr.nl_pid = 0;  // the kernel assigns a port id
  // The request: a netlink header, a connector header and the operation, one after another.
  alignas(nlmsghdr) std::uint8_t request[NLMSG_SPACE(sizeof(cn_msg) + sizeof(proc_cn_mcast_op))] = {};
  auto* header = reinterpret_cast<nlmsghdr*>(request);
  header->nlmsg_len = NLMSG_LENGTH(sizeof(cn_msg) + sizeof(proc_cn_mcast_op));
  header->nlmsg_type = NLMSG_DONE;
  auto* message = static_cast<cn_msg*>(NLMSG_DATA(header));
  message->id.idx = CN_IDX_PROC;
  message->id.val = CN_VAL_PROC;
  message->len = sizeof(proc_cn_mcast_op);
  const proc_cn_mcast_op op = PROC_CN_MCAST_LISTEN;
  std::memcpy(message->data, &op, sizeof op);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::send(fd, request, header->nlmsg_len, 0) < 0) {
    ::close(fd);
    return false;
  }
  events_fd_ = fd;
  return true;
}

void PeerWatch::DrainExitEvents() {
  if (events_fd_ < 0) return;
  alignas(nlmsghdr) char buffer[8192];
  for (;;) {
    const ssize_t n = ::recv(events_fd_, buffer, sizeof buffer, 0);
    if (n <= 0) {
      if (n < 0 && errno == ENOBUFS) continue;  // events were dropped; later ones still come
      return;
    }
    int len = static_cast<int>(n);
    for (auto* h = reinterpret_cast<nlmsghdr*>(buffer); NLMSG_OK(h, len); h = NLMSG_NEXT(h, len)) {
      const auto* message = static_cast<const cn_msg*>(NLMSG_DATA(h));
      const auto* event = reinterpret_cast<const proc_event*>(message->data);
      if (event->what != proc_event::PROC_EVENT_EXIT) continue;
      const auto& e = event->event_data.exit;
      if (e.process_pid != e.process_tgid) continue;  // a thread, not the process
      for (int i = 0; i < kRosterSize; ++i) {
        if (peers_[i].pid == e.process_tgid) exit_status_[i] = static_cast<int>(e.exit_code);
      }
    }
  }
}

}  // namespace rths::lockstep
