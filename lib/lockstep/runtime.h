#pragma once
/// @file Lockstep runtime shared by every participant: channels, handshake, step mailboxes,
/// cached answers, the silence watchdog and the event loop. The protocol and its step-index
/// table are in docs/lockstep.md; every participant's doc comment points there.
///
/// The same participant objects run as separate processes, each with its own LCM instance on
/// `udpm://` (one UDP port per run), or all in one process sharing one `memq://` instance
/// (memq queues belong to one lcm_t, so in that mode LCM dispatches from one thread).
#include <array>
#include <exception>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "rths/handshake_t.hpp"

namespace rths::lockstep {

inline constexpr const char* kChHandshake = "RTHS_HANDSHAKE";
inline constexpr const char* kChDesired = "RTHS_DESIRED";
inline constexpr const char* kChCommand = "RTHS_COMMAND";
inline constexpr const char* kChMeasured = "RTHS_MEASURED";
inline constexpr const char* kChCurrent = "RTHS_CURRENT";
inline constexpr const char* kChAck = "RTHS_ACK";

enum Phase : std::int8_t { kRequest = 1, kHello = 2, kGo = 3, kAbort = 4, kDone = 5, kBye = 6 };

/// Process exit codes, documented in docs/lockstep.md and `rths --help`.
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,          ///< bad command line or scenario (nothing ran)
  kExitLockstep = 3,       ///< this participant detected a protocol failure (silence, hash mismatch)
  kExitPeerAbort = 4,      ///< stopped because another participant broadcast ABORT
  kExitInternal = 5,       ///< an exception in this participant's own computation
  kExitSafety = 6,         ///< the safety monitor stopped the run (a limit was left)
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

/// Runtime knobs (from scenario [lockstep]).
struct Timing {
  double timeout_ms = 250.0;        ///< silence before the clock re-requests a step
  int max_attempts = 8;             ///< requests of one step before the clock aborts
  double handshake_timeout_s = 20;  ///< wait for every HELLO (clock) / for GO (others)
};

/// Test-only fault injection (never set by a scenario; see tests/lockstep_test.cpp).
struct Faults {
  std::int64_t drop_first_request_at = -1;  ///< behave as if the first copy of desired k was lost
  std::int64_t stall_at = -1;               ///< stop answering from step k on (a hung process)
  std::int64_t throw_at = -1;               ///< throw from the step computation at step k
  std::int64_t crash_at = -1;               ///< die by SIGABRT at step k (a crashed process)
  double command_gain = 1.0;                ///< controller: multiply u_k (-1: a sign error)
};

/// Encodes an lcm-gen message into `out` (reusing its capacity: no allocation once sized).
template <class Msg>
void Encode(const Msg& msg, Bytes* out) {
  const int n = msg.getEncodedSize();
  if (out->size() != static_cast<std::size_t>(n)) out->resize(n);
  msg.encode(out->data(), 0, n);
}

/// Received messages of one channel, kept by step index k in a small ring, decoded into
/// preallocated slots. The first copy of (channel, k) is "new"; later copies are duplicates.
template <class Msg, int kDepth = 4>
class StepMailbox {
 public:
  enum class Put { kNew, kDuplicate, kStale, kForeign, kBad };

  StepMailbox() { ks_.fill(-1); }

  /// Decodes `rbuf`; keeps it if it is the first copy of its k for this run.
  Put Add(const lcm::ReceiveBuffer* rbuf, std::int64_t run_id) {
    if (scratch_.decode(rbuf->data, 0, rbuf->data_size) < 0) return Put::kBad;
    if (scratch_.run_id != run_id) return Put::kForeign;
    const std::int64_t k = scratch_.k;
    if (k < 0) return Put::kBad;
    last_k_ = k;
    const int slot = static_cast<int>(k % kDepth);
    if (ks_[slot] == k) return Put::kDuplicate;
    if (ks_[slot] > k) return Put::kStale;
    std::swap(slots_[slot], scratch_);
    ks_[slot] = k;
    return Put::kNew;
  }
  /// The message of step k, or nullptr if it has not arrived (or has left the ring).
  const Msg* Get(std::int64_t k) const {
    if (k < 0) return nullptr;
    const int slot = static_cast<int>(k % kDepth);
    return ks_[slot] == k ? &slots_[slot] : nullptr;
  }
  /// k of the message just added (valid after Add returned kNew, kDuplicate or kStale).
  std::int64_t last_k() const { return last_k_; }
  /// Forgets step k (test-only fault injection: behave as if it had never arrived).
  void Forget(std::int64_t k) {
    const int slot = static_cast<int>(k % kDepth);
    if (ks_[slot] == k) ks_[slot] = -1;
  }

 private:
  std::array<Msg, kDepth> slots_{};
  std::array<std::int64_t, kDepth> ks_{};
  Msg scratch_{};
  std::int64_t last_k_ = -1;
};

/// Encoded answers of the last few steps, so a repeated request gets the very same bytes.
class AnswerCache {
 public:
  static constexpr int kDepth = 4;
  AnswerCache() { ks_.fill(-1); }
  /// Slot to encode the answer of step k into (then call Commit(k)).
  Bytes* Slot(std::int64_t k) { return &bytes_[k % kDepth]; }
  void Commit(std::int64_t k) { ks_[k % kDepth] = k; }
  const Bytes* Get(std::int64_t k) const {
    return (k >= 0 && ks_[k % kDepth] == k) ? &bytes_[k % kDepth] : nullptr;
  }

 private:
  std::array<Bytes, kDepth> bytes_{};
  std::array<std::int64_t, kDepth> ks_{};
};

/// Base of every participant: handshake, ABORT/DONE handling, the watchdog on the clock,
/// failure bookkeeping. A subclass subscribes to its step channels and implements the step.
class Participant {
 public:
  Participant(std::string name, RunIdentity id, Timing timing, lcm::LCM* lcm);
  virtual ~Participant() = default;
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  const std::string& name() const { return name_; }
  bool finished() const { return finished_; }
  /// Exit code once finished (ExitCode).
  int exit_code() const { return exit_code_; }
  /// Why it failed ("" on success).
  const std::string& error() const { return error_; }

  /// Called by the event loop after every handled message and on every poll timeout.
  virtual void Poll(SteadyClock::time_point now);

  Faults faults;  ///< test-only

 protected:
  /// Called once when GO arrives (the clock calls it itself).
  virtual void OnGo() {}
  /// Called once when DONE arrives, before BYE is sent: flush and close outputs.
  virtual void OnDone() {}
  /// Called when the run stops abnormally (ABORT or own failure): flush what is committed.
  virtual void OnStop() {}

  /// Publishes raw bytes on a channel.
  void PublishBytes(const char* channel, const Bytes& bytes);
  /// Encodes an answer for step k into the cache, then publishes it.
  template <class Msg>
  void Answer(const char* channel, AnswerCache* cache, std::int64_t k, const Msg& msg) {
    Encode(msg, cache->Slot(k));
    cache->Commit(k);
    PublishBytes(channel, *cache->Get(k));
  }
  /// Re-publishes cached answers of steps k and k+1 (a re-request of step k).
  void Republish(const char* channel, const AnswerCache& cache, std::int64_t k);

  /// Marks the clock as alive (call on every message from the clock).
  void HeardClock(SteadyClock::time_point now) { last_clock_ = now; }
  /// Stops this participant with an exit code; broadcasts ABORT when `broadcast`.
  void Fail(int exit_code, const std::string& reason, bool broadcast, std::int64_t k = -1);
  /// Stops cleanly.
  void Finish();
  /// Sends a handshake message of this participant; `roster` (GO only) lists who takes part,
  /// every one of them with this participant's scenario hash (the clock checked them).
  void SendHandshake(Phase phase, std::int64_t k = -1, const std::string& reason = "",
                     const std::vector<std::string>* roster = nullptr);

  bool running() const { return running_ && !finished_; }

  /// Fault injection (test-only): true exactly once, for the first copy of request k.
  bool InjectDrop(std::int64_t k) {
    if (faults.drop_first_request_at != k || dropped_) return false;
    dropped_ = true;
    return true;
  }
  /// Fault injection (test-only): this participant no longer answers from step k on.
  bool Stalled(std::int64_t k) const { return faults.stall_at >= 0 && k >= faults.stall_at; }
  /// Fault injection (test-only): throws from (or crashes in) the step computation of step k.
  void MaybeThrow(std::int64_t k) const;
  /// Runs a message handler body, turning an exception into a clean, broadcast failure.
  template <class F>
  void Guarded(std::int64_t k, F&& body) {
    try {
      body();
    } catch (const std::exception& e) {
      OnStop();
      Fail(kExitInternal, name_ + ": step " + std::to_string(k) + ": " + e.what(), true, k);
    }
  }
  bool IsClock() const { return is_clock_; }

  const std::string name_;
  const RunIdentity id_;
  const Timing timing_;
  lcm::LCM* const lcm_;
  bool is_clock_ = false;

 private:
  void OnHandshake(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  bool running_ = false;
  bool finished_ = false;
  int exit_code_ = kExitOk;
  std::string error_;
  SteadyClock::time_point created_;
  SteadyClock::time_point last_clock_;
  rths::handshake_t hs_in_{};
  rths::handshake_t hs_out_{};
  Bytes hs_bytes_;
  std::int64_t foreign_messages_ = 0;
  bool dropped_ = false;

 protected:
  /// Handshake messages addressed to the clock (HELLO, BYE, ABORT from others).
  virtual void OnHandshakeForClock(const rths::handshake_t& /*msg*/, SteadyClock::time_point /*now*/) {}
};

/// Runs participants sharing one LCM instance until every one has finished. In udpm mode the
/// vector holds one participant; in memq mode all of them. Returns the first non-zero exit
/// code of a participant that failed on its own (not kExitPeerAbort), else the first
/// non-zero, else 0.
int RunLoop(lcm::LCM* lcm, const std::vector<Participant*>& participants);

/// Checks the host can do LCM multicast on loopback (`udpm`); returns "" if fine, or a message
/// telling the user how to fix it (ip route add 224.0.0.0/4 dev lo).
std::string CheckMulticastRoute();

}  // namespace rths::lockstep
