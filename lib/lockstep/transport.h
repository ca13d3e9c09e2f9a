#pragma once
/// @file The per-channel udpm transport: every channel of a run on a UDP port of its own, so a
/// process receives only the channels it subscribes to (docs/lockstep.md, "Transports").
///
/// On one port every udpm datagram reaches every socket of the run, the sender's included: 5
/// messages x 5 processes = 25 deliveries per step, 10 of them to processes that drop them. With a
/// port per channel a step costs 15 deliveries, each one wanted. The datagrams are LCM's own
/// (small-message format "LC02": magic, sequence number, channel, NUL, payload), so `lcm-spy`,
/// `lcm-logger` and any LCM program read and write them on the channel's port; but the sockets are
/// our own and are read in the event loop's thread, without LCM's receive thread and its notify
/// pipe (two extra wake-ups per delivery in LCM 1.3.1).
///
/// The URL of such a run is the base URL with `port_per_channel=1`:
/// `udpm://239.255.76.67:PORT?ttl=0&port_per_channel=1`. Channel i of kPortChannels travels on
/// PORT + i; the plain LCM URL of one channel is UdpmUrl::ChannelUrl.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lockstep/runtime.h"

namespace rths::lockstep {

/// The channels of a run in port order: channel i travels on base port + i.
inline constexpr std::array<const char*, 7> kPortChannels{kChHandshake, kChDesired, kChCommand, kChMeasured,
                                                          kChCurrent,   kChAck,     kChRepair};
/// Port offset of a run channel (its index in kPortChannels), -1 for any other channel.
int PortOffset(std::string_view channel);

/// A parsed `udpm://GROUP:PORT?opt=value&...` URL.
struct UdpmUrl {
  std::string group = "239.255.76.67";  ///< multicast group (IPv4)
  int port = 7667;                      ///< UDP port; per channel: the base port (PORT .. PORT+6)
  int ttl = 0;                          ///< multicast TTL, [0, 255]: 0 stays on this host
  int recv_buf_size = 0;                ///< SO_RCVBUF of every receive socket [bytes]; 0: the default
  bool port_per_channel = false;        ///< option `port_per_channel=1`: one port per channel
  std::string other_options;            ///< any other options, "a=1&b=2", passed on to LCM

  /// Parses `url`; nullopt (and `*error` says why) if it is not a udpm:// URL of this form.
  static std::optional<UdpmUrl> Parse(const std::string& url, std::string* error = nullptr);
  /// The plain LCM URL that carries `channel` (per channel: its own port; else the run's port),
  /// e.g. for `lcm-spy --lcm-url` or a supervisor's one-off ABORT.
  std::string ChannelUrl(std::string_view channel) const;
  /// The URL back as text (the run's URL, with port_per_channel=1 when set).
  std::string ToString() const;
};

/// True if `url` is a udpm:// URL asking for a port per channel (`port_per_channel=1`).
bool IsPortPerChannel(const std::string& url);

/// Sockets of one process on a per-channel run: one receive socket per subscribed channel (bound
/// to its port, member of the group) and one send socket. Read by HandleTimeout in the caller's
/// thread. Nothing is allocated per message: one receive buffer, headers sent with sendmsg.
class UdpmChannels {
 public:
  /// Called with every message of a subscribed channel (rbuf->data: the payload).
  using Callback = void (*)(void* context, const lcm::ReceiveBuffer* rbuf);

  /// Opens the send socket. `url.port_per_channel` must be set. Check good() afterwards.
  explicit UdpmChannels(const UdpmUrl& url);
  ~UdpmChannels();
  UdpmChannels(const UdpmChannels&) = delete;
  UdpmChannels& operator=(const UdpmChannels&) = delete;

  /// False if a socket could not be opened, bound or joined to the group (error() says which).
  bool good() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  /// Calls `callback(context, rbuf)` for every message on `channel` (one of kPortChannels),
  /// opening its receive socket on first use. False (and error() says why) if it cannot.
  bool Subscribe(const char* channel, Callback callback, void* context);
  /// Sends `size` bytes on `channel` (one of kPortChannels) as one LCM datagram. 0 on success,
  /// -1 on failure (an unknown channel, a message too large for one datagram, a send error).
  int Publish(const char* channel, const void* data, unsigned size);
  /// Waits at most `timeout_ms` for a message on any subscribed channel, then hands at most one
  /// waiting message per channel to its callbacks; before a handshake message (an ABORT, DONE) it
  /// hands over every message waiting on the other channels, sent before it, as on one port. Returns how many it handled (> 0), 0 if none
  /// came in time, < 0 on a receive error (errno set; EINTR: a signal).
  int HandleTimeout(int timeout_ms);

  /// Datagrams received and sent so far (all channels).
  std::int64_t received() const { return received_; }
  std::int64_t sent() const { return sent_; }

 private:
  struct Socket {
    int fd = -1;
    const char* channel = nullptr;
    std::vector<std::pair<Callback, void*>> callbacks;
  };
  bool Dispatch(Socket* s);

  UdpmUrl url_;
  std::string error_;
  int send_fd_ = -1;
  std::uint32_t seqno_ = 0;
  std::array<Socket, kPortChannels.size()> sockets_{};
  std::vector<int> poll_order_;  ///< indices of open receive sockets, in opening order
  std::array<std::uint8_t, 65536> buffer_{};
  std::int64_t received_ = 0, sent_ = 0;
};

/// RunLoop on a per-channel transport (participants attached with Participant::Attach).
int RunLoop(UdpmChannels* channels, const std::vector<Participant*>& participants,
            const volatile std::sig_atomic_t* stop = nullptr);

}  // namespace rths::lockstep
