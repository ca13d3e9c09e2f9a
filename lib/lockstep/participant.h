#pragma once
/// @file The base of every lockstep participant: subscriptions (through the fault injector),
/// handshake, ABORT / DONE / CLOSE handling, the repair of lost messages, the watchdog on the
/// clock and failure bookkeeping (docs/lockstep.md; every participant's doc comment points there).
///
/// The same participant objects run as separate processes, each with its own LCM instance on
/// `udpm://` (one UDP port per run), or each with the sockets of a per-channel run (UdpmChannels,
/// lockstep/transport.h: one UDP port per channel), or all in one process and one thread on one
/// in-process queue (a memq run: InprocChannels, lockstep/transport.h). A participant on an LCM
/// instance of its own (`memq://` too) is still supported (tests, participants of your own).
#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lockstep/answer_cache.h"
#include "lockstep/config.h"
#include "core/exit_code.h"
#include "lockstep/faults.h"
#include "lockstep/follow_ledger.h"
#include "lockstep/link_stats.h"
#include "lockstep/mailbox.h"
#include "lockstep/peer_watch.h"
#include "lockstep/protocol.h"
#include "lockstep/realtime.h"
#include "lockstep/step_mailboxes.h"
#include "lockstep/want_list.h"
#include "lockstep/wiring.h"
#include "rths/handshake_t.hpp"
#include "rths/repair_t.hpp"

namespace rths::lockstep {

class Channels;

/// Follow mode's knobs (Participant::Follow; `--follow-idle-s`, `--follow-queue`).
struct FollowOptions {
  double idle_exit_s = 2.0;  ///< finish after this long without a message, once one came [s]
  double start_wait_s = 60.0;  ///< ... and before the first one (time to start lcm-logplayer) [s]
  /// Messages LCM may hold per subscription before it drops one (LCM's default: 30). Deep, so that
  /// a participant held off the CPU for a while catches up instead of losing its inputs: 50 000 is
  /// 25 s of one channel at 2 kHz.
  int queue_capacity = 50000;
};

/// A subclass subscribes to its step channels, declares its answer channel, lists what it lacks
/// for a step, and implements the step (StepParticipant and ClockParticipant, from the step table).
class Participant {
 public:
  /// `lcm`: the LCM instance to subscribe and publish on, or nullptr for a participant that is
  /// then attached to a per-channel transport (Attach) before it runs.
  Participant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm, Faults faults = {});
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
  /// Clock only: what it saw of every participant of the roster (nullptr for the others).
  virtual const std::array<PeerObservation, kRosterSize>* peers() const { return nullptr; }
  /// Paced clock only: when the next step is to be released (the event loop sleeps until then
  /// with clock_nanosleep on CLOCK_MONOTONIC); time_point::max() if no release is pending.
  virtual SteadyClock::time_point ReleaseAt() const { return SteadyClock::time_point::max(); }
  /// Paced clock only: how long before ReleaseAt() the event loop stops sleeping and busy-waits
  /// ([realtime] spin_us; zero: it sleeps to the release).
  virtual SteadyClock::duration SpinBeforeRelease() const { return {}; }

  /// Stops now, as if the supervisor had said ABORT (an interrupt): flushes, exit kExitPeerAbort.
  void Interrupt(const std::string& reason);
  /// Follow mode (a participant fed by `lcm-logplayer`, docs/replay.md): no handshake and no
  /// clock; it starts at once, answers each step as soon as its inputs arrive, and finishes after
  /// `o.idle_exit_s` without a message (`o.start_wait_s` before the first). Nothing re-requests a lost message: a step
  /// participant answers a step whose input was lost from the input before it (StepParticipant,
  /// zero-order hold) and keeps a FollowLedger of what it did.
  void Follow(const FollowOptions& o);
  /// Follow mode only: what it did with every step (nullptr otherwise, and for the clock).
  virtual const FollowLedger* follow_ledger() const { return nullptr; }
  /// The logger only: steps whose signals.csv row waited for its writer thread (a full queue);
  /// -1 for the others.
  virtual std::int64_t output_stalls() const { return -1; }

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
  /// Appends to `out` the inputs this participant lacks to give its answers that the barrier of
  /// step k waits for (derived from the step table: StepParticipant, ClockParticipant). Called
  /// when the clock re-requests step k.
  virtual void Lacks(std::int64_t /*k*/, WantList* /*out*/) const {}

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
  virtual void Count(Channel channel, Put put, std::int64_t k);
  /// Called for a step input new to its mailbox: its channel, its step k and its bytes.
  using OnNewInput = std::function<void(Channel channel, std::int64_t k, const lcm::ReceiveBuffer* rbuf)>;
  /// Subscribes to every channel `role` reads (wiring.h), each with the wake-up the step table
  /// gives it: a message is dropped once this participant has finished, otherwise put in its
  /// mailbox in `boxes` and counted (duplicate, stale, foreign, repaired); a new one is passed to
  /// `on_new`. The one input path of every step participant and of the clock.
  void SubscribeInputs(const ResolvedRole& role, StepMailboxes* boxes, OnNewInput on_new);
  /// Sends a repair_t for step k listing `wants` (remembered, to count what gets repaired).
  void SendRepair(std::int64_t k, const WantList& wants);

  /// Follow mode: a message of step k of this run arrives on `channel`, before it is stored (a step
  /// participant answers, from held inputs, the steps it now knows will never be complete).
  virtual void BeforeFollowInput(Channel /*channel*/, std::int64_t /*k*/) {}
  /// Follow mode: the feed has gone quiet; called once, before the participant finishes.
  virtual void OnFollowEnd() {}
  /// Follow mode: set up before the feed starts (sizes its ledger).
  virtual void OnFollowStart() {}
  bool following() const { return follow_; }

  /// Marks the clock as alive (call on every message from the clock).
  void HeardClock(SteadyClock::time_point now) { last_clock_ = now; }
  /// Stops this participant with an exit code; broadcasts ABORT when `broadcast`. `culprit`
  /// names the participant to blame when it is not this one.
  void Fail(int exit_code, const std::string& reason, bool broadcast, std::int64_t k = -1,
            const std::string& culprit = "");
  /// Stops cleanly.
  void Finish();
  /// An ABORT from someone outside the roster (`sender`, e.g. kMonitorSender) handed to this
  /// participant in-process: sends it to every participant as that sender's handshake ABORT, then
  /// stops as on hearing it (kExitPeerAbort, "<sender> aborted the run: <reason>").
  void RelayAbort(const std::string& sender, const std::string& reason, std::int64_t k);
  /// Stops as on an ABORT heard from `sender` (kExitPeerAbort, "<sender> aborted the run: <reason>").
  void StopOnAbortFrom(const std::string& sender, const std::string& reason, std::int64_t k);
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
  const LockstepConfig timing_;
  lcm::LCM* const lcm_;
  Channels* channels_ = nullptr;  ///< set by Attach (then lcm_ is unused)
  bool is_clock_ = false;
  LinkStats stats_;
  double stepping_s_ = 0;

  /// Every handshake message of this run, our own included (the logger records them).
  virtual void OnHandshakeSeen(const lcm::ReceiveBuffer* /*rbuf*/, const rths::handshake_t& /*msg*/) {}
  /// Handshake messages addressed to the clock (HELLO, BYE).
  virtual void OnHandshakeForClock(const rths::handshake_t& /*msg*/, SteadyClock::time_point /*now*/) {}
  /// An ABORT from another participant (before this one stops).
  virtual void OnAbortFrom(const std::string& /*participant*/, const std::string& /*reason*/) {}
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
  double follow_start_s_ = 0;
  bool follow_heard_ = false;  ///< follow mode: a message has arrived
  SteadyClock::time_point linger_since_;
  int exit_code_ = kExitOk;
  std::string error_;
  std::string culprit_;
  std::int64_t fail_step_ = -1;
  SteadyClock::time_point created_;
  SteadyClock::time_point last_clock_;
  bool heard_clock_ = false;  ///< a step message from the clock since the last Tick (it sets last_clock_)
  bool said_hello_ = false;
  SteadyClock::time_point last_beat_;  ///< our last HEARTBEAT (or HELLO)
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

}  // namespace rths::lockstep
