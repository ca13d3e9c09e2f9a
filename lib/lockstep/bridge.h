#pragma once
/// @file The transport of a mixed run (`rths run --external ROLE`, docs/lockstep.md
/// "Transports"): every built-in participant in this process on one in-process queue
/// (InprocChannels), and only the external participants on udpm, bridged here. A step costs the
/// built-in participants what a memq run costs them, plus one UDP round trip to each external
/// participant on the critical path.
///
/// What crosses the bridge, per external role (from the run's wiring):
///   out (queue -> udpm): the channels it reads, every handshake message (REQUEST, GO, DONE,
///     CLOSE, ABORT...), every repair_t (re-requests of its answers, and others' wants it may hold);
///   in (udpm -> queue): its answer channel; the handshake and repair_t messages whose
///     `participant` is an external role. Our own messages, looped back by multicast, are dropped
///     by the same rule (they carry a built-in role's name).
/// Payloads are LCM's: the external participant cannot tell a mixed run from an all-udpm one.
/// The udpm side is UdpmChannels on the run's one port, read in this thread between the queue's
/// messages (no LCM receive thread and notify pipe: one wake-up per datagram, not three, and
/// nothing allocated per message).
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "lockstep/transport.h"
#include "lockstep/wiring.h"

namespace rths::lockstep {

class BridgedChannels final : public Channels {
 public:
  /// Opens the sockets of `udpm_url` (a plain udpm:// URL: port_per_channel is refused) for
  /// `external_roles` of `wiring`. Check good() afterwards.
  BridgedChannels(const std::string& udpm_url, const std::vector<std::string>& external_roles, const Wiring& wiring);
  ~BridgedChannels() override;
  BridgedChannels(const BridgedChannels&) = delete;
  BridgedChannels& operator=(const BridgedChannels&) = delete;

  /// A subscription on the in-process queue (messages from outside are put on it).
  bool Subscribe(const char* channel, Callback callback, void* context, Wake wake = Wake::kOnArrival) override;
  /// On the queue, and on udpm if an external role needs it.
  int Publish(const char* channel, const void* data, unsigned size) override;
  /// Hands over what is queued; with nothing queued, waits at most `timeout_ms` for a datagram
  /// from outside, then hands it over.
  int HandleTimeout(int timeout_ms) override;

  /// Messages sent out to and taken in from the external participants so far.
  std::int64_t sent_out() const { return sent_out_; }
  std::int64_t taken_in() const { return taken_in_; }

 private:
  /// A message of channel kPortChannels[channel] from the udpm side.
  void OnOuter(int channel, const lcm::ReceiveBuffer* rbuf);
  struct Inlet {  ///< the context of one channel's subscription on the udpm side
    BridgedChannels* bridge = nullptr;
    int channel = 0;
  };

  InprocChannels inner_;
  std::unique_ptr<UdpmChannels> outer_;
  std::array<Inlet, kPortChannels.size()> inlets_{};
  std::array<bool, kPortChannels.size()> out_{};  ///< by PortOffset: sent out
  std::array<bool, kPortChannels.size()> in_{};   ///< by PortOffset: taken in
  std::vector<std::string> external_;
  std::int64_t sent_out_ = 0, taken_in_ = 0;
};

}  // namespace rths::lockstep
