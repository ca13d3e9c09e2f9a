#pragma once
/// @file The lockstep protocol's vocabulary (docs/lockstep.md): channel names and codes,
/// handshake phases, what every participant of a run agrees on, and the encoding helpers.
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace rths::lockstep {

inline constexpr const char* kChHandshake = "RTHS_HANDSHAKE";
inline constexpr const char* kChDesired = "RTHS_DESIRED";
inline constexpr const char* kChCommand = "RTHS_COMMAND";
inline constexpr const char* kChMeasured = "RTHS_MEASURED";
inline constexpr const char* kChCurrent = "RTHS_CURRENT";
inline constexpr const char* kChAck = "RTHS_ACK";
inline constexpr const char* kChRepair = "RTHS_REPAIR";

/// Per-step channels by code (the codes travel in repair_t.want_channel).
enum Channel : std::int8_t { kNoChannel = 0, kDesired = 1, kCommand = 2, kMeasured = 3, kCurrent = 4, kAck = 5 };
/// The number of per-step channel codes (kNoChannel included): arrays indexed by Channel.
inline constexpr int kChannelCodes = 6;
/// Name of a per-step channel ("" for kNoChannel or an unknown code).
const char* ChannelName(std::int8_t code);

enum Phase : std::int8_t {
  kRequest = 1,  ///< clock: who is there? (repeated until every HELLO is in)
  kHello = 2,    ///< participant: here I am, with my scenario hash
  kGo = 3,       ///< clock: everyone agrees; step 0 follows
  kAbort = 4,    ///< anyone (or the supervisor): stop now
  kDone = 5,     ///< clock: every step is committed; flush (repeated until every BYE is in)
  kBye = 6,      ///< participant: flushed; answered to every DONE while lingering
  kClose = 7,    ///< clock: every BYE is in; lingering participants exit
  kHeartbeat = 8,  ///< participant: alive (every heartbeat_s it declared in HELLO; PeerWatch)
};

using SteadyClock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;

/// What every participant of one run agrees on (checked by the handshake).
struct RunIdentity {
  std::int64_t run_id = 0;
  std::string scenario_sha256;
  std::int64_t n_steps = 0;
  double dt_s = 0.0;
};

/// A fresh random run id (62 bits, odd: never 0), for a new run or replay.
std::int64_t NewRunId();

/// Encodes an lcm-gen message into `out` (reusing its capacity: no allocation once sized).
template <class Msg>
void Encode(const Msg& msg, Bytes* out) {
  const int n = msg.getEncodedSize();
  if (out->size() != static_cast<std::size_t>(n)) out->resize(n);
  msg.encode(out->data(), 0, n);
}

/// The run_id and k of an encoded step or repair message (the first two int64 fields after the
/// 8-byte type hash), without decoding it; false if it is too short.
bool PeekRunAndStep(const std::uint8_t* data, std::size_t size, std::int64_t* run_id, std::int64_t* k);

/// Whether a message on a subscribed channel wakes the participant's event loop. Only the
/// per-channel udpm transport (UdpmChannels) acts on it; the others hand every message over as it
/// comes.
enum class Wake : std::int8_t {
  kOnArrival,  ///< wake up for it (every channel by default)
  /// Do not wake up for it: it is read, before anything else, whenever a kOnArrival message wakes
  /// the loop, and at the loop's timeouts (at most 5 ms apart). For a channel whose message of
  /// step k is always sent before a message this participant does wake for, which then finds it
  /// queued (loopback multicast hands a datagram to every socket at once): a wake-up saved per step.
  kLater,
};

}  // namespace rths::lockstep
