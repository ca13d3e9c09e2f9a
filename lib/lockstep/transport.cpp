#include "lockstep/transport.h"

#include "lockstep/live_feed.h"

#include "lockstep/run_loop.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

namespace rths::lockstep {

namespace {
/// LCM's small-message datagram: uint32 magic "LC02", uint32 sequence number (both big-endian),
/// the channel and its NUL, then the payload (LCM 1.3.1, lcm_udpm.c).
constexpr std::uint32_t kShortMagic = 0x4c433032;
/// The largest datagram LCM sends unfragmented.
constexpr std::size_t kMaxShortDatagram = 65499;

std::int64_t WallUtime() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}
}  // namespace

int PortOffset(std::string_view channel) {
  for (std::size_t i = 0; i < kPortChannels.size(); ++i) {
    if (channel == kPortChannels[i]) return static_cast<int>(i);
  }
  return -1;
}

std::optional<UdpmUrl> UdpmUrl::Parse(const std::string& url, std::string* error) {
  auto fail = [&](const std::string& why) -> std::optional<UdpmUrl> {
    if (error) *error = fmt::format("{}: {} (expected udpm://GROUP:PORT?ttl=0[&port_per_channel=1])", url, why);
    return std::nullopt;
  };
  constexpr std::string_view kScheme = "udpm://";
  if (url.rfind(kScheme, 0) != 0) return fail("not a udpm:// URL");
  const std::string rest = url.substr(kScheme.size());
  const std::size_t q = rest.find('?');
  const std::string host = rest.substr(0, q);
  const std::string query = q == std::string::npos ? "" : rest.substr(q + 1);
  UdpmUrl u;
  const std::size_t colon = host.find(':');
  u.group = host.substr(0, colon);
  if (u.group.empty()) u.group = "239.255.76.67";
  in_addr a{};
  if (::inet_pton(AF_INET, u.group.c_str(), &a) != 1) return fail("the group is not an IPv4 address");
  if (colon != std::string::npos) {
    try {
      std::size_t used = 0;
      u.port = std::stoi(host.substr(colon + 1), &used);
      if (used != host.size() - colon - 1) return fail("bad port");
    } catch (const std::exception&) {
      return fail("bad port");
    }
  }
  std::size_t start = 0;
  while (start < query.size()) {
    std::size_t amp = query.find('&', start);
    if (amp == std::string::npos) amp = query.size();
    const std::string opt = query.substr(start, amp - start);
    start = amp + 1;
    if (opt.empty()) continue;
    const std::size_t eq = opt.find('=');
    const std::string key = opt.substr(0, eq), value = eq == std::string::npos ? "" : opt.substr(eq + 1);
    auto number = [&](int* out) {
      try {
        std::size_t used = 0;
        *out = std::stoi(value, &used);
        return used == value.size();
      } catch (const std::exception&) {
        return false;
      }
    };
    if (key == "ttl") {
      if (!number(&u.ttl) || u.ttl < 0 || u.ttl > 255) return fail("ttl must be in [0, 255]");
    } else if (key == "recv_buf_size") {
      if (!number(&u.recv_buf_size) || u.recv_buf_size < 0) return fail("recv_buf_size must be >= 0");
    } else if (key == "port_per_channel") {
      if (value != "0" && value != "1" && value != "true" && value != "false") {
        return fail("port_per_channel must be 1 or 0");
      }
      u.port_per_channel = value == "1" || value == "true";
    } else {
      u.other_options += (u.other_options.empty() ? "" : "&") + opt;
    }
  }
  const int last = u.PortOf(static_cast<int>(kPortChannels.size()) - 1);
  if (u.port < 1 || last > 65535) {
    return fail(u.port_per_channel ? "ports PORT .. PORT+6 must be in [1, 65535]" : "port must be in [1, 65535]");
  }
  return u;
}

std::string UdpmUrl::ChannelUrl(std::string_view channel) const {
  std::string s = fmt::format("udpm://{}:{}?ttl={}", group, PortOf(std::max(0, PortOffset(channel))), ttl);
  if (recv_buf_size > 0) s += fmt::format("&recv_buf_size={}", recv_buf_size);
  if (!other_options.empty()) s += "&" + other_options;
  return s;
}

std::string UdpmUrl::ToString() const {
  std::string s = fmt::format("udpm://{}:{}?ttl={}", group, port, ttl);
  if (recv_buf_size > 0) s += fmt::format("&recv_buf_size={}", recv_buf_size);
  if (port_per_channel) s += "&port_per_channel=1";
  if (!other_options.empty()) s += "&" + other_options;
  return s;
}

bool IsPortPerChannel(const std::string& url) {
  const auto u = UdpmUrl::Parse(url);
  return u && u->port_per_channel;
}

UdpmChannels::UdpmChannels(const UdpmUrl& url) : url_(url), buffers_(kBatch * kBufferBytes) {
  for (std::size_t i = 0; i < kPortChannels.size(); ++i) sockets_[i].channel = static_cast<int>(i);
  to_.sin_family = AF_INET;
  ::inet_pton(AF_INET, url_.group.c_str(), &to_.sin_addr);  // checked by UdpmUrl::Parse
  send_fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (send_fd_ < 0) {
    error_ = fmt::format("cannot create a UDP socket: {}", std::strerror(errno));
    return;
  }
  const unsigned char ttl = static_cast<unsigned char>(url_.ttl), loop = 1;
  if (::setsockopt(send_fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
      ::setsockopt(send_fd_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0) {
    error_ = fmt::format("cannot set the multicast TTL / loopback: {}", std::strerror(errno));
  }
}

UdpmChannels::~UdpmChannels() {
  if (send_fd_ >= 0) ::close(send_fd_);
  for (auto& s : sockets_) {
    if (s.fd >= 0) ::close(s.fd);
  }
}

int UdpmChannels::OpenReceiveSocket(int port, const char* channel) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error_ = fmt::format("cannot create a UDP socket: {}", std::strerror(errno));
    return -1;
  }
  const int one = 1;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  ip_mreq m{};
  ::inet_pton(AF_INET, url_.group.c_str(), &m.imr_multiaddr);
  m.imr_interface.s_addr = htonl(INADDR_ANY);
  std::string why;
  // As LCM does: SO_REUSEADDR, so every process of the run (and lcm-spy) binds the same port.
  if (::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) {
    why = "SO_REUSEADDR";
  } else if (url_.recv_buf_size > 0 &&
             ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &url_.recv_buf_size, sizeof url_.recv_buf_size) != 0) {
    why = "SO_RCVBUF";
  } else if (::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    why = fmt::format("bind to port {}", port);
  } else if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m) != 0) {
    why = fmt::format("join {}", url_.group);
  }
  if (!why.empty()) {
    error_ = fmt::format("{} ({}): {}", why, channel, std::strerror(errno));
    ::close(fd);
    return -1;
  }
  return fd;
}

bool UdpmChannels::Subscribe(const char* channel, Callback callback, void* context, Wake wake) {
  const int i = PortOffset(channel);
  if (i < 0) {
    error_ = fmt::format("channel {} has no port of its own (not a run channel)", channel);
    return false;
  }
  Socket& s = sockets_[url_.PortOf(i) - url_.port];  // on one port, sockets_[0] for every channel
  if (s.fd < 0) {
    s.fd = OpenReceiveSocket(url_.PortOf(i), channel);
    if (s.fd < 0) return false;
    poll_order_.push_back(s.channel);
  }
  s.wakes = s.wakes || wake == Wake::kOnArrival || !url_.port_per_channel;
  callbacks_[i].emplace_back(callback, context);
  return true;
}

int UdpmChannels::Publish(const char* channel, const void* data, unsigned size) {
  // The clock's live records (lockstep/live_feed.h) travel on the handshake's port: a monitor
  // listens there, and the participants' sockets drop another channel's datagrams.
  const int i = std::strcmp(channel, kChMonitor) == 0 ? 0 : PortOffset(channel);
  if (i < 0 || send_fd_ < 0) return -1;
  const std::size_t channel_len = std::strlen(channel) + 1;
  if (8 + channel_len + size > kMaxShortDatagram) return -1;  // LCM would fragment: not needed here
  const std::uint32_t header[2] = {htonl(kShortMagic), htonl(seqno_++)};
  iovec iov[3] = {{const_cast<std::uint32_t*>(header), sizeof header},
                  {const_cast<char*>(channel), channel_len},
                  {const_cast<void*>(data), size}};
  sockaddr_in to = to_;
  to.sin_port = htons(static_cast<std::uint16_t>(url_.PortOf(i)));
  msghdr msg{};
  msg.msg_name = &to;
  msg.msg_namelen = sizeof to;
  msg.msg_iov = iov;
  msg.msg_iovlen = 3;
  if (::sendmsg(send_fd_, &msg, 0) < 0) return -1;
  ++sent_;
  return 0;
}

void UdpmChannels::Deliver(Socket* s, std::uint8_t* datagram, std::size_t size) {
  ++received_;
  if (size < 9) return;
  std::uint32_t magic = 0;
  std::memcpy(&magic, datagram, 4);
  if (ntohl(magic) != kShortMagic) return;  // a fragment of a large message: none of ours
  const auto* channel = reinterpret_cast<const char*>(datagram + 8);
  const auto* end = static_cast<const char*>(std::memchr(channel, '\0', size - 8));
  if (!end) return;
  const int i = PortOffset(std::string_view(channel, static_cast<std::size_t>(end - channel)));
  // Not a run channel (the clock's live records), or per channel another channel on our port.
  if (i < 0 || (url_.port_per_channel && i != s->channel)) return;
  const std::size_t header = 8 + static_cast<std::size_t>(end - channel) + 1;
  lcm::ReceiveBuffer rb{datagram + header, static_cast<std::uint32_t>(size - header), WallUtime()};
  for (const auto& [callback, context] : callbacks_[i]) callback(context, &rb);
}

bool UdpmChannels::Dispatch(Socket* s) {
  const ssize_t n = ::recv(s->fd, buffers_.data(), kBufferBytes, 0);
  if (n < 0) return false;  // EAGAIN: another reader took it, or nothing after all
  Deliver(s, buffers_.data(), static_cast<std::size_t>(n));
  return true;
}

int UdpmChannels::Drain(Socket* s) {
  std::array<iovec, kBatch> iov{};
  std::array<mmsghdr, kBatch> msgs{};
  int handled = 0;
  while (handled < 256) {  // bounded under a flood
    for (int i = 0; i < kBatch; ++i) {
      iov[i] = {buffers_.data() + i * kBufferBytes, kBufferBytes};
      msgs[i] = {};
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
    }
    const int n = ::recvmmsg(s->fd, msgs.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (n <= 0) break;  // EAGAIN: nothing (more) waiting
    // Hand them over only after the call: a callback may publish, never receive, meanwhile.
    for (int i = 0; i < n; ++i) Deliver(s, buffers_.data() + i * kBufferBytes, msgs[i].msg_len);
    handled += n;
    if (n < kBatch) break;  // the queue is empty: no further call to find that out
  }
  return handled;
}

int UdpmChannels::HandleTimeout(int timeout_ms) {
  if (!url_.port_per_channel) {  // one FIFO: everything in arrival order
    Socket& s = sockets_[0];
    if (s.fd < 0) return ::poll(nullptr, 0, timeout_ms);
    pollfd fd{s.fd, POLLIN, 0};
    const int r = ::poll(&fd, 1, timeout_ms);
    return r <= 0 ? r : Drain(&s);
  }
  std::array<pollfd, kPortChannels.size()> fds{};
  std::array<Socket*, kPortChannels.size()> socks{};
  std::size_t n = 0;
  for (const int i : poll_order_) {
    if (!sockets_[i].wakes) continue;
    socks[n] = &sockets_[i];
    fds[n++] = {sockets_[i].fd, POLLIN, 0};
  }
  const int r = ::poll(fds.data(), n, timeout_ms);
  if (r < 0) return r;
  // What does not wake us was sent before what did (or is found at the timeout): it goes first.
  int handled = 0;
  for (const int i : poll_order_) {
    if (!sockets_[i].wakes) handled += Drain(&sockets_[i]);
  }
  if (r == 0) return handled;
  Socket* handshake = nullptr;
  for (std::size_t j = 0; j < n; ++j) {
    if (!(fds[j].revents & POLLIN)) continue;
    Socket* s = socks[j];
    if (s->channel == 0) {
      handshake = s;
    } else if (Dispatch(s)) {
      ++handled;
    }
  }
  if (handshake) {
    // Across ports there is no order: an ABORT may be ready before step messages sent earlier.
    // Loopback delivery is done within the sender's send call, so whatever was sent before this
    // handshake message is queued by now: hand it all over first, as one port's FIFO would.
    for (const int i : poll_order_) {
      if (&sockets_[i] != handshake) handled += Drain(&sockets_[i]);
    }
    if (Dispatch(handshake)) ++handled;
  }
  return handled;
}

namespace {
/// Bytes reserved in every queue slot up front: more than any step message of a 20-story
/// structure, so a run allocates nothing per message after its set-up.
constexpr std::size_t kInprocSlotBytes = 1024;
}  // namespace

InprocChannels::InprocChannels() : ring_(16) {
  for (auto& m : ring_) m.bytes.reserve(kInprocSlotBytes);
  current_.bytes.reserve(kInprocSlotBytes);
}

bool InprocChannels::Subscribe(const char* channel, Callback callback, void* context, Wake) {
  const int i = PortOffset(channel);
  if (i < 0) {
    error_ = fmt::format("channel {} is not a run channel", channel);
    return false;
  }
  callbacks_[i].emplace_back(callback, context);
  return true;
}

int InprocChannels::Publish(const char* channel, const void* data, unsigned size) {
  const int i = PortOffset(channel);
  if (i < 0) return -1;
  if (count_ == ring_.size()) {
    // Full: double the ring, oldest first (only while the run's largest backlog is first reached).
    std::vector<Message> bigger(2 * ring_.size());
    for (std::size_t j = 0; j < count_; ++j) bigger[j] = std::move(ring_[(head_ + j) % ring_.size()]);
    for (std::size_t j = count_; j < bigger.size(); ++j) bigger[j].bytes.reserve(kInprocSlotBytes);
    ring_ = std::move(bigger);
    head_ = 0;
  }
  Message& m = ring_[(head_ + count_) % ring_.size()];
  m.channel = i;
  // Only handshake messages need their receive time (the logger stamps those before GO); a clock
  // read per step message would cost more than the queue itself.
  m.utime = i == 0 ? WallUtime() : 0;
  const auto* p = static_cast<const std::uint8_t*>(data);
  m.bytes.assign(p, p + size);  // within the slot's capacity once warmed up
  ++count_;
  ++sent_;
  return 0;
}

int InprocChannels::HandleTimeout(int timeout_ms) {
  if (count_ == 0) {
    if (timeout_ms > 0) {
      const timespec ts{timeout_ms / 1000, (timeout_ms % 1000) * 1000000L};
      if (::nanosleep(&ts, nullptr) != 0) return -1;  // errno EINTR: a signal
    }
    return 0;
  }
  int handled = 0;
  while (count_ > 0 && handled < kMaxBatch) {
    // Swap the message out of its slot: a handler may publish, reusing the slot, meanwhile.
    std::swap(current_, ring_[head_]);
    head_ = (head_ + 1) % ring_.size();
    --count_;
    lcm::ReceiveBuffer rb{current_.bytes.data(), static_cast<std::uint32_t>(current_.bytes.size()), current_.utime};
    for (const auto& [callback, context] : callbacks_[current_.channel]) callback(context, &rb);
    ++handled;
  }
  return handled;
}

int RunLoop(Channels* channels, const std::vector<Participant*>& participants,
            const volatile std::sig_atomic_t* stop) {
  return RunLoopWith([channels](int timeout_ms) { return channels->HandleTimeout(timeout_ms); }, participants,
                     stop);
}

std::string CheckMulticastRoute() {
  // /proc/net/route: Iface Destination Gateway Flags RefCnt Use Metric Mask ... (hex, little-endian)
  std::ifstream in("/proc/net/route");
  if (!in) return "";  // not Linux-like; let LCM decide
  std::string line;
  std::getline(in, line);  // header
  const std::uint32_t group = 0x010000E0;  // 224.0.0.1 in /proc's byte order
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string iface;
    unsigned long dest = 0, gw = 0, flags = 0, refcnt = 0, use = 0, metric = 0, mask = 0;
    ss >> iface >> std::hex >> dest >> gw >> flags >> std::dec >> refcnt >> use >> metric >> std::hex >>
        mask;
    if (!ss) continue;
    if ((group & mask) == dest && (flags & 0x1)) return "";
  }
  return "this host has no route for multicast (224.0.0.0/4), so LCM's udpm transport cannot work.\n"
         "Fix (as root):  ip route add 224.0.0.0/4 dev lo";
}

}  // namespace rths::lockstep
