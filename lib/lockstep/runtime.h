#pragma once
/// @file Lockstep runtime shared by every participant: channels, handshake, step mailboxes,
/// cached answers, the repair of lost messages, the silence watchdog, fault injection and the
/// event loop. The protocol and its step-index table are in docs/lockstep.md; every
/// participant's doc comment points there.
///
/// The same participant objects run as separate processes, each with its own LCM instance on
/// `udpm://` (one UDP port per run), or each with the sockets of a per-channel run (UdpmChannels,
/// lockstep/transport.h: one UDP port per channel), or all in one process and one thread on one
/// in-process queue (a memq run: InprocChannels, lockstep/transport.h). A participant on an LCM
/// instance of its own (`memq://` too) is still supported (tests, participants of your own).
#include <array>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lockstep/faults.h"
#include "lockstep/realtime.h"
#include "rths/handshake_t.hpp"
#include "rths/repair_t.hpp"

namespace rths::lockstep {

class Channels;

/// Lockstep runtime knobs (docs/lockstep.md).
struct LockstepConfig {
  /// Re-request an incomplete step after this silence [ms], [5, 10000]; each further re-request
  /// of the same step waits twice as long, up to max(rerequest_ms, 1000 ms).
  double rerequest_ms = 100.0;
  /// Stop the run when one step has not completed for this long [s], [1, 3600] and at least
  /// 4 rerequest_ms: a participant that stopped answering. A loaded host only slows steps down.
  double stall_budget_s = 10.0;
  double handshake_timeout_s = 20; ///< abort if not every participant said hello, [0.1, 600]
  bool operator==(const LockstepConfig&) const = default;
};

inline constexpr const char* kChHandshake = "RTHS_HANDSHAKE";
inline constexpr const char* kChDesired = "RTHS_DESIRED";
inline constexpr const char* kChCommand = "RTHS_COMMAND";
inline constexpr const char* kChMeasured = "RTHS_MEASURED";
inline constexpr const char* kChCurrent = "RTHS_CURRENT";
inline constexpr const char* kChAck = "RTHS_ACK";
inline constexpr const char* kChRepair = "RTHS_REPAIR";

/// Per-step channels by code (the codes travel in repair_t.want_channel).
enum Channel : std::int8_t { kNoChannel = 0, kDesired = 1, kCommand = 2, kMeasured = 3, kCurrent = 4, kAck = 5 };
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
};

/// Process exit codes, documented in docs/lockstep.md, the README and `rths --help`.
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,          ///< bad command line or scenario, or not enough disk (nothing ran)
  kExitLockstep = 3,       ///< a protocol failure (a participant stopped answering, hash mismatch)
  kExitPeerAbort = 4,      ///< stopped because another participant (or the supervisor) said ABORT
  kExitInternal = 5,       ///< an exception in this participant's own computation
  kExitSafety = 6,         ///< the safety monitor stopped the run (a limit was left)
  kExitOutput = 7,         ///< the run's output could not be written (disk full, I/O error)
  kExitRealtime = 8,       ///< real-time mode: the miss policy stopped the run (docs/realtime.md)
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

/// Runtime knobs (from the scenario's [lockstep] table; ranges in docs/scenarios.md).
struct Timing {
  /// The longest silence before the clock re-requests an incomplete step [ms]. When steps are
  /// fast it re-requests sooner: after 8 typical step times, at least kMinRerequestS. Each
  /// further re-request of the same step waits twice as long, up to max(rerequest_ms, 1000 ms).
  double rerequest_ms = 100.0;
  /// A step that has not completed after this long [s] stops the run, naming who stopped
  /// answering. Participants give up on a silent clock after stall_budget_s + 2 s.
  double stall_budget_s = 10.0;
  double handshake_timeout_s = 20;  ///< wait for every HELLO (clock) / for GO (others) [s]

  /// The shortest wait before a first re-request [s].
  static constexpr double kMinRerequestS = 1e-3;
  /// Wait before re-request number `n` (1-based) of one step [s], when a step typically takes
  /// `typical_step_s` (0 if not known yet).
  double RerequestAfterS(int n, double typical_step_s) const;
  /// How long a participant that heard nothing from the clock keeps waiting [s].
  double WatchdogS() const { return stall_budget_s + 2.0; }
  /// How long a participant lingers after DONE, answering repeated DONEs, without CLOSE [s].
  double LingerS() const;
  /// The clock's real-time pacing ([realtime]; off: as fast as the participants answer).
  Pacing pacing;
};

/// Counters of what the link lost and what the protocol repaired (summary.json, per participant).
struct LinkStats {
  std::int64_t rerequests = 0;         ///< clock: re-requests it sent (repair_t of an incomplete step)
  std::int64_t steps_rerequested = 0;  ///< clock: steps that needed at least one re-request
  std::int64_t repair_requests = 0;    ///< repair_t it sent listing inputs it lacked
  std::int64_t resent = 0;             ///< messages it re-sent from its cache because one lacked them
  std::int64_t repaired = 0;           ///< messages it lacked, asked for, and then received
  std::int64_t duplicates = 0;         ///< copies of messages it already held (ignored)
  std::int64_t stale = 0;              ///< messages of steps it had left behind (ignored)
  std::int64_t foreign = 0;            ///< messages of another run on the same port (ignored)
  InjectedFaults injected;             ///< faults injected on its receive path ([faults])
};

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

/// What a mailbox did with a message.
enum class Put { kNew, kDuplicate, kStale, kForeign, kBad };

/// Received messages of one channel, kept by step index k in a small ring, decoded into
/// preallocated slots. The first copy of (channel, k) is "new"; later copies are duplicates.
template <class Msg, int kDepth = 4>
class StepMailbox {
 public:
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

/// Messages a participant lacks: (channel, step) pairs, at most kCapacity.
class WantList {
 public:
  static constexpr int kCapacity = 8;
  void Add(Channel channel, std::int64_t k) {
    if (n_ < kCapacity && k >= 0) items_[n_++] = {channel, k};
  }
  int size() const { return n_; }
  bool empty() const { return n_ == 0; }
  Channel channel(int i) const { return items_[i].channel; }
  std::int64_t k(int i) const { return items_[i].k; }

 private:
  struct Item {
    Channel channel;
    std::int64_t k;
  };
  std::array<Item, kCapacity> items_{};
  int n_ = 0;
};

/// Base of every participant: subscriptions (through the fault injector), handshake, ABORT /
/// DONE / CLOSE handling, the repair of lost messages, the watchdog on the clock and failure
/// bookkeeping. A subclass subscribes to its step channels, declares its answer channel, lists
/// what it lacks for a step, and implements the step.
class Participant {
 public:
  /// `lcm`: the LCM instance to subscribe and publish on, or nullptr for a participant that is
  /// then attached to a per-channel transport (Attach) before it runs.
  Participant(std::string name, RunIdentity id, Timing timing, lcm::LCM* lcm, Faults faults = {});
  virtual ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  const std::string& name() const { return name_; }
  bool finished() const { return finished_; }
  /// Exit code once finished (ExitCode).
  int exit_code() const { return exit_code_; }
  /// Why it failed ("" on success).
  const std::string& error() const { return error_; }
  /// The participant this one blames for its failure ("" if none or itself): the one that
  /// stopped answering.
  const std::string& culprit() const { return culprit_; }
  /// The step being run when it failed (-1 before step 0 or on success).
  std::int64_t fail_step() const { return fail_step_; }
  const LinkStats& stats() const { return stats_; }
  /// Clock only: wall-clock time from GO to the last committed step [s] (0 for the others).
  double stepping_s() const { return stepping_s_; }
  /// Clock only: step latencies and deadline misses (nullptr for the others).
  virtual const RealtimeStats* realtime() const { return nullptr; }
  /// Paced clock only: when the next step is to be released (the event loop sleeps until then
  /// with clock_nanosleep on CLOCK_MONOTONIC); time_point::max() if no release is pending.
  virtual SteadyClock::time_point ReleaseAt() const { return SteadyClock::time_point::max(); }

  /// Stops now, as if the supervisor had said ABORT (an interrupt): flushes, exit kExitPeerAbort.
  void Interrupt(const std::string& reason);
  /// Follow mode (a participant fed by `lcm-logplayer`, docs/replay.md): no handshake and no
  /// clock; it starts at once, answers each step as soon as its inputs arrive, and finishes
  /// (exit 0) after `idle_exit_s` without a message of its run. Nothing re-requests a lost
  /// message: a lost input stops its answers there.
  void Follow(double idle_exit_s);

  /// Moves every subscription, and every publication from now on, to `channels` (a per-channel
  /// udpm run, or the in-process queue of a memq run). For a participant built with
  /// lcm = nullptr, before RunLoop; `channels` must outlive it. Throws std::runtime_error if a
  /// channel cannot be opened.
  void Attach(Channels* channels);

  /// Called by the event loop after every handled message and on every poll timeout: delivers
  /// held (delayed) messages that are due, then Poll(). `idle` is true when no message was
  /// waiting: only then may a participant conclude that someone has gone silent.
  void Tick(SteadyClock::time_point now, bool idle);
  /// The next moment Tick() has something to do without a message arriving (a held message is
  /// due, a re-request); time_point::max() if none.
  SteadyClock::time_point NextDeadline() const;

 protected:
  using Handler = std::function<void(const lcm::ReceiveBuffer*)>;
  /// Subscribes `handler` to `channel`; every message passes the fault injector first. `wake`:
  /// whether its messages wake this participant (per-channel udpm; see Wake).
  void Subscribe(const char* channel, Handler handler, Wake wake = Wake::kOnArrival);
  /// Declares this participant's per-step answer channel and its cache: a repair_t that wants
  /// (channel, k) gets the cached bytes of k re-sent.
  void SetAnswerChannel(Channel channel, const AnswerCache* cache);

  virtual void Poll(SteadyClock::time_point now, bool idle);
  /// When Poll() next has something to do (default: never; the event loop still polls often).
  virtual SteadyClock::time_point PollDeadline() const { return SteadyClock::time_point::max(); }
  /// Called once when GO (or, if GO was lost, the first message of step 0) arrives.
  virtual void OnGo() {}
  /// Called once when DONE arrives, before BYE is sent: flush and close outputs. A non-empty
  /// return is a failure to flush (exit kExitOutput, ABORT broadcast).
  virtual std::string OnDone() { return {}; }
  /// Called when the run stops abnormally (ABORT or own failure): flush what is committed.
  virtual void OnStop() {}
  /// Appends to `out` the inputs this participant lacks to advance up to step k (its answer of
  /// k; for the plant measured_t k+1, or measured_t k if "ideal"). Called when the clock
  /// re-requests step k.
  virtual void ListMissing(std::int64_t /*k*/, WantList* /*out*/) const {}

  /// Publishes raw bytes on a channel (LCM or the attached channels); 0 on success.
  int Send(const char* channel, const std::uint8_t* data, std::size_t size);
  /// Publishes raw bytes on a channel.
  void PublishBytes(const char* channel, const Bytes& bytes);
  /// Encodes an answer for step k into the cache, then publishes it.
  template <class Msg>
  void Answer(const char* channel, AnswerCache* cache, std::int64_t k, const Msg& msg) {
    Encode(msg, cache->Slot(k));
    cache->Commit(k);
    PublishBytes(channel, *cache->Get(k));
  }
  /// Counts what a mailbox did with a message (duplicates, stale, foreign; repaired inputs).
  void Count(Channel channel, Put put, std::int64_t k);
  /// Adds a message to a mailbox and counts it.
  template <class Msg, int D>
  Put Receive(StepMailbox<Msg, D>* box, Channel channel, const lcm::ReceiveBuffer* rbuf) {
    const Put put = box->Add(rbuf, id_.run_id);
    Count(channel, put, box->last_k());
    return put;
  }
  /// Sends a repair_t for step k listing `wants` (remembered, to count what gets repaired).
  void SendRepair(std::int64_t k, const WantList& wants);

  /// Marks the clock as alive (call on every message from the clock).
  void HeardClock(SteadyClock::time_point now) { last_clock_ = now; }
  /// Stops this participant with an exit code; broadcasts ABORT when `broadcast`. `culprit`
  /// names the participant to blame when it is not this one.
  void Fail(int exit_code, const std::string& reason, bool broadcast, std::int64_t k = -1,
            const std::string& culprit = "");
  /// Stops cleanly.
  void Finish();
  /// Sends a handshake message of this participant; `roster` (GO only) lists who takes part,
  /// every one of them with this participant's scenario hash (the clock checked them).
  void SendHandshake(Phase phase, std::int64_t k = -1, const std::string& reason = "",
                     const std::vector<std::string>* roster = nullptr);

  bool running() const { return running_ && !finished_; }
  /// Process fault (test and rehearsal, [faults.process]): this participant no longer answers
  /// from step k on.
  bool Stalled(std::int64_t k) const {
    return faults_.process == ProcessFault::kStall && k >= faults_.at_step;
  }
  /// Process fault: throws from (or crashes, kills or stops the process in) the step computation
  /// of step k.
  void MaybeFault(std::int64_t k);
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
  const Faults& faults() const { return faults_; }

  const std::string name_;
  const RunIdentity id_;
  const Timing timing_;
  lcm::LCM* const lcm_;
  Channels* channels_ = nullptr;  ///< set by Attach (then lcm_ is unused)
  bool is_clock_ = false;
  LinkStats stats_;
  double stepping_s_ = 0;

  /// Every handshake message of this run, our own included (the logger records them).
  virtual void OnHandshakeSeen(const lcm::ReceiveBuffer* /*rbuf*/, const rths::handshake_t& /*msg*/) {}
  /// Handshake messages addressed to the clock (HELLO, BYE).
  virtual void OnHandshakeForClock(const rths::handshake_t& /*msg*/, SteadyClock::time_point /*now*/) {}
  /// A repair_t from another participant, seen by the clock (who is alive, what it lacks).
  virtual void OnRepairForClock(const rths::repair_t& /*msg*/) {}

 private:
  struct Route;
  /// A received message: through the fault injector, then DeliverNow.
  void Deliver(Route* route, const lcm::ReceiveBuffer* rbuf);
  /// Hands a message to its handler (held messages come back here, past the injector).
  void DeliverNow(Route* route, const lcm::ReceiveBuffer* rbuf);
  void OnHandshake(const lcm::ReceiveBuffer* rbuf);
  void OnRepair(const lcm::ReceiveBuffer* rbuf);
  void StartRunning();

  Faults faults_;
  FaultInjector injector_;
  std::vector<std::unique_ptr<Route>> routes_;
  bool running_ = false;
  bool finished_ = false;
  bool lingering_ = false;  ///< after DONE and BYE: answering repeated DONEs until CLOSE
  bool follow_ = false;     ///< follow mode (Follow())
  double follow_idle_s_ = 0;
  SteadyClock::time_point linger_since_;
  int exit_code_ = kExitOk;
  std::string error_;
  std::string culprit_;
  std::int64_t fail_step_ = -1;
  SteadyClock::time_point created_;
  SteadyClock::time_point last_clock_;
  std::int64_t last_clock_step_ = -1;  ///< the latest step the clock requested, as seen here
  rths::handshake_t hs_in_{};
  rths::handshake_t hs_out_{};
  rths::repair_t repair_in_{};
  rths::repair_t repair_out_{};
  Bytes hs_bytes_;
  Bytes repair_bytes_;
  Channel answer_channel_ = kNoChannel;
  const AnswerCache* answer_cache_ = nullptr;
  /// Messages asked for in a repair_t and not yet received (to count `repaired`).
  std::array<std::pair<Channel, std::int64_t>, 16> asked_{};
  int asked_next_ = 0;
  bool fault_fired_ = false;
};

/// Runs participants sharing one LCM instance until every one has finished. In udpm mode the
/// vector holds one participant; in memq mode all of them. Returns the first non-zero exit
/// code of a participant that failed on its own (not kExitPeerAbort), else the first
/// non-zero, else 0.
/// When `*stop` becomes true (an interrupt), every participant stops at once (exit
/// kExitPeerAbort, "interrupted"), its committed output flushed.
int RunLoop(lcm::LCM* lcm, const std::vector<Participant*>& participants,
            const volatile std::sig_atomic_t* stop = nullptr);
/// RunLoop over any transport: `handle(timeout_ms)` waits at most that long and handles what
/// came in, returning as lcm::LCM::handleTimeout does (> 0 handled, 0 timed out, < 0 error).
int RunLoopWith(const std::function<int(int)>& handle, const std::vector<Participant*>& participants,
                const volatile std::sig_atomic_t* stop = nullptr);

/// Checks the host can do LCM multicast on loopback (`udpm`); returns "" if fine, or a message
/// telling the user how to fix it (ip route add 224.0.0.0/4 dev lo).
std::string CheckMulticastRoute();

}  // namespace rths::lockstep
