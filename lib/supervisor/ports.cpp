#include "supervisor/ports.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::supervisor {

namespace {

/// Binds a UDP socket to `port` (0: any) and returns the port bound, or -1 if it is taken.
int BindUdp(int port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) throw Error("", "cannot create a UDP socket to pick a port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  socklen_t len = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  ::close(fd);
  return ok ? ntohs(a.sin_port) : -1;
}

}  // namespace

int FreeUdpPort() {
  const int port = BindUdp(0);
  if (port < 0) throw Error("", "cannot pick a free UDP port");
  return port;
}

int FreeUdpPorts(int n) {
  for (int attempt = 0; attempt < 64; ++attempt) {
    const int base = FreeUdpPort();
    if (base + n - 1 > 65535) continue;
    bool free = true;
    for (int i = 1; i < n && free; ++i) free = BindUdp(base + i) >= 0;
    if (free) return base;
  }
  throw Error("", fmt::format("cannot find {} consecutive free UDP ports", n));
}

}  // namespace rths::supervisor
