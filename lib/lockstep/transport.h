#pragma once
/// @file The per-channel udpm transport: every channel of a run on a UDP port of its own, so a
/// process receives only the channels it subscribes to (docs/lockstep.md, "Transports").
///
/// On one port every udpm datagram reaches every socket of the run, the sender's included: 5
/// messages x 5 processes = 25 deliveries per step, 11 of them to processes that drop them. With a
/// port per channel a step costs 14 deliveries, each one wanted. The datagrams are LCM's own
/// (small-message format "LC02": magic, sequence number, channel, NUL, payload), so `lcm-spy`,
/// `lcm-logger` and any LCM program read and write them on the channel's port; but the sockets are
/// our own and are read in the event loop's thread, without LCM's receive thread and its notify
/// pipe (two extra wake-ups per delivery in LCM 1.3.1).
///
/// The URL of such a run is the base URL with `port_per_channel=1`:
/// `udpm://239.255.76.67:PORT?ttl=0&port_per_channel=1`. Channel i of kPortChannels travels on
/// PORT + i; the plain LCM URL of one channel is UdpmUrl::ChannelUrl.
#include <netinet/in.h>

#include <array>
#include <csignal>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lockstep/protocol.h"

namespace rths::lockstep {

class Participant;

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
  /// The UDP port of the run channel with index `channel` in kPortChannels: PORT + index per
  /// channel, PORT on one port.
  int PortOf(int channel) const { return port + (port_per_channel ? channel : 0); }
  /// The plain LCM URL that carries `channel` (per channel: its own port; else the run's port),
  /// e.g. for `lcm-spy --lcm-url` or a supervisor's one-off ABORT.
  std::string ChannelUrl(std::string_view channel) const;
  /// The URL back as text (the run's URL, with port_per_channel=1 when set).
  std::string ToString() const;
};

/// True if `url` is a udpm:// URL asking for a port per channel (`port_per_channel=1`).
bool IsPortPerChannel(const std::string& url);

/// What a participant publishes on and subscribes through when it is not on an LCM instance
/// (Participant::Attach): the per-channel udpm sockets (UdpmChannels) or the in-process queue of a
/// memq run (InprocChannels). Only the run's channels (kPortChannels) are carried.
class Channels {
 public:
  /// Called with every message of a subscribed channel (rbuf->data: the payload).
  using Callback = void (*)(void* context, const lcm::ReceiveBuffer* rbuf);
  virtual ~Channels() = default;

  /// False if the transport could not be set up (error() says why).
  bool good() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  /// Calls `callback(context, rbuf)` for every message on `channel` (one of kPortChannels). False
  /// (and error() says why) if it cannot. `wake`: whether its messages wake HandleTimeout (Wake;
  /// a transport may hand every message over as it comes regardless).
  virtual bool Subscribe(const char* channel, Callback callback, void* context, Wake wake = Wake::kOnArrival) = 0;
  /// Sends `size` bytes on `channel` (one of kPortChannels). 0 on success, -1 on failure.
  virtual int Publish(const char* channel, const void* data, unsigned size) = 0;
  /// Waits at most `timeout_ms` for a message, then hands what came in to the callbacks. Returns
  /// how many it handled (> 0), 0 if none came in time, < 0 on an error (errno set; EINTR: a
  /// signal), as lcm::LCM::handleTimeout does.
  virtual int HandleTimeout(int timeout_ms) = 0;

 protected:
  std::string error_;
};

/// Sockets of one process on a udpm run, read by HandleTimeout in the caller's thread: per channel
/// (`port_per_channel=1`), one receive socket per subscribed channel, bound to its port; on one
/// port (a plain LCM URL: the bridge of a mixed run, BridgedChannels), one receive socket for
/// every channel, read in arrival order, as LCM's own one-port transport hands messages over but
/// without its receive thread. Either way one send socket, and nothing allocated per message: the
/// receive buffers are made once, headers sent with sendmsg.
class UdpmChannels final : public Channels {
 public:
  /// Opens the send socket. Check good() afterwards (false if a socket could not be opened, bound
  /// or joined to the group; error() says which).
  explicit UdpmChannels(const UdpmUrl& url);
  ~UdpmChannels() override;
  UdpmChannels(const UdpmChannels&) = delete;
  UdpmChannels& operator=(const UdpmChannels&) = delete;

  /// Opens the channel's receive socket on first use (on one port: the one socket). A socket wakes
  /// HandleTimeout if any of its subscriptions is Wake::kOnArrival; on one port every message wakes.
  bool Subscribe(const char* channel, Callback callback, void* context, Wake wake = Wake::kOnArrival) override;
  /// One LCM datagram; -1 for an unknown channel, a message too large for one datagram, a send
  /// error.
  int Publish(const char* channel, const void* data, unsigned size) override;
  /// On one port: waits for a datagram, then hands over every one waiting, in arrival order.
  /// Per channel: waits for a message on a channel that wakes (Wake::kOnArrival); then first hands over every
  /// message waiting on the channels that do not wake (sent before the one that woke it, or
  /// found at the timeout), then at most one waiting message per waking channel; before a
  /// handshake message (an ABORT, DONE) it hands over every message waiting on the other
  /// channels, sent before it, as on one port.
  int HandleTimeout(int timeout_ms) override;

  /// Datagrams received and sent so far (all channels).
  std::int64_t received() const { return received_; }
  std::int64_t sent() const { return sent_; }

 private:
  struct Socket {
    int fd = -1;
    int channel = 0;     ///< index in kPortChannels of the channel it carries (per channel)
    bool wakes = false;  ///< in the poll set: some subscription is Wake::kOnArrival
  };
  /// Opens, binds and joins the receive socket of `port`; -1 (and error_ says why, naming
  /// `channel`) if it cannot.
  int OpenReceiveSocket(int port, const char* channel);
  /// Receives one datagram from `s` and hands it over; false if none was waiting.
  bool Dispatch(Socket* s);
  /// Receives every datagram waiting on `s` (recvmmsg, kBatch at a time, at most 256) and hands
  /// them over; how many.
  int Drain(Socket* s);
  /// Hands one received datagram to its channel's callbacks (if it is an LCM message of a run
  /// channel, and per channel, of the socket's own channel).
  void Deliver(Socket* s, std::uint8_t* datagram, std::size_t size);

  /// Datagrams received per recvmmsg call, and the size of each receive buffer (the largest datagram).
  static constexpr int kBatch = 8;
  static constexpr std::size_t kBufferBytes = 65536;

  UdpmUrl url_;
  sockaddr_in to_{};  ///< the group at the base port (a channel's port is set per send)
  int send_fd_ = -1;
  std::uint32_t seqno_ = 0;
  std::array<Socket, kPortChannels.size()> sockets_{};  ///< per channel; on one port sockets_[0] only
  std::array<std::vector<std::pair<Callback, void*>>, kPortChannels.size()> callbacks_{};  ///< per channel
  std::vector<int> poll_order_;  ///< indices of open receive sockets, in opening order
  std::vector<std::uint8_t> buffers_;  ///< kBatch receive buffers of 64 KiB, one after another
  std::int64_t received_ = 0, sent_ = 0;
};

/// The in-process transport of a memq run (`rths run --transport memq`, the reproductions, replay):
/// every participant in one process and one thread, attached to one of these. A publish appends
/// the message to one FIFO queue; HandleTimeout hands queued messages to their subscribers in
/// publish order, the messages their handlers publish included. It replaces LCM's `memq://`
/// provider, which costs per message a malloc and free, a write and a read on a notify pipe, and
/// a regular-expression match of the channel against every subscription (LCM 1.3.1); the
/// payloads, and the order in which every participant sees them, are the same (lockstep_test,
/// transport_test). Nothing is allocated per message once the queue has grown to the run's
/// largest backlog (a handful of messages): every slot holds 1 KiB from the start.
class InprocChannels final : public Channels {
 public:
  InprocChannels();
  /// `wake` is ignored: every message is handed over in publish order.
  bool Subscribe(const char* channel, Callback callback, void* context, Wake wake = Wake::kOnArrival) override;
  /// Copies the message into the queue; -1 for a channel that is not a run channel.
  int Publish(const char* channel, const void* data, unsigned size) override;
  /// Hands queued messages over, up to kMaxBatch (then returns, so the caller's timers run);
  /// with none queued it sleeps `timeout_ms` (in one thread nothing can arrive meanwhile: the
  /// caller's deadlines, a held message or a re-request, are what it waits for) and returns 0.
  int HandleTimeout(int timeout_ms) override;

  /// Messages handed over per HandleTimeout at most.
  static constexpr int kMaxBatch = 64;
  /// Messages published so far.
  std::int64_t sent() const { return sent_; }
  /// Messages queued, not yet handed over.
  std::size_t queued() const { return count_; }

 private:
  struct Message {
    int channel = -1;
    std::int64_t utime = 0;
    Bytes bytes;
  };
  std::array<std::vector<std::pair<Callback, void*>>, kPortChannels.size()> callbacks_;
  std::vector<Message> ring_;  ///< the queue: count_ messages from head_, wrapping
  std::size_t head_ = 0, count_ = 0;
  Message current_;  ///< the message being handed over (swapped out of the ring)
  std::int64_t sent_ = 0;
};

/// RunLoop on a transport of our own (participants attached with Participant::Attach).
int RunLoop(Channels* channels, const std::vector<Participant*>& participants,
            const volatile std::sig_atomic_t* stop = nullptr);

/// Checks the host can do LCM multicast on loopback (`udpm`); returns "" if fine, or a message
/// telling the user how to fix the host (ip route add 224.0.0.0/4 dev lo). What a program can do
/// instead is the program's to say (participants::MulticastRouteAdvice).
std::string CheckMulticastRoute();

}  // namespace rths::lockstep
