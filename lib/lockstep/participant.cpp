#include "lockstep/participant.h"

#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include <fmt/core.h>

#include "lockstep/abort.h"
#include "lockstep/step_table.h"
#include "lockstep/transport.h"

namespace rths::lockstep {

namespace {
double SecondsBetween(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// Copies of ABORT, GO and CLOSE sent at once (each is also recovered otherwise; see
/// docs/lockstep.md): a single loss then costs nothing.
constexpr int kControlCopies = 3;
}  // namespace

/// One subscription of one participant: LCM calls OnMessage, which passes the fault injector.
struct Participant::Route {
  Participant* self;
  std::string channel;
  Handler handler;
  /// What a message of step k on this channel proves about the clock.
  enum Evidence {
    kNothing,    ///< not a step channel
    kRequest,    ///< desired_t: it requested step k
    kAnswer,     ///< command_t, current_t: they answer desired_t k, so it requested step k
    kNextState,  ///< measured_t: it follows command_t k-1, so it requested step k-1
  };
  Evidence step_evidence = kNothing;
  Wake wake = Wake::kOnArrival;
  lcm::Subscription* subscription = nullptr;  ///< on an LCM instance (its queue capacity: follow mode)
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string&) { self->Deliver(this, rbuf); }
  static void OnChannelMessage(void* route, const lcm::ReceiveBuffer* rbuf) {
    auto* r = static_cast<Route*>(route);
    r->self->Deliver(r, rbuf);
  }
};

Participant::Participant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm, Faults faults)
    : name_(std::move(name)),
      id_(std::move(id)),
      timing_(config),
      lcm_(lcm),
      faults_(std::move(faults)),
      injector_(faults_, std::hash<std::string>{}(name_)) {
  created_ = SteadyClock::now();
  last_clock_ = created_;
  for (auto& a : asked_) a = {kNoChannel, -1};
  Subscribe(kChHandshake, [this](const lcm::ReceiveBuffer* rbuf) { OnHandshake(rbuf); });
  Subscribe(kChRepair, [this](const lcm::ReceiveBuffer* rbuf) { OnRepair(rbuf); });
}

Participant::~Participant() = default;

void Participant::Subscribe(const char* channel, Handler handler, Wake wake) {
  const std::string_view ch(channel);
  const Route::Evidence evidence = ch == kChDesired                       ? Route::kRequest
                                   : (ch == kChCommand || ch == kChCurrent) ? Route::kAnswer
                                   : ch == kChMeasured                      ? Route::kNextState
                                                                            : Route::kNothing;
  routes_.push_back(std::make_unique<Route>(Route{this, channel, std::move(handler), evidence, wake}));
  if (channels_) {
    if (!channels_->Subscribe(channel, &Route::OnChannelMessage, routes_.back().get(), wake)) {
      throw std::runtime_error(fmt::format("{}: {}", name_, channels_->error()));
    }
  } else if (lcm_) {
    routes_.back()->subscription = lcm_->subscribe(channel, &Route::OnMessage, routes_.back().get());
  }
}

void Participant::SubscribeInputs(const ResolvedRole& role, StepMailboxes* boxes, OnNewInput on_new) {
  for (int c = kDesired; c < kChannelCodes; ++c) {
    if (!role.reads[c]) continue;
    const auto channel = static_cast<Channel>(c);
    Subscribe(ChannelName(channel), [this, channel, boxes, on_new](const lcm::ReceiveBuffer* rbuf) {
      if (finished()) return;
      std::int64_t k = -1;
      if (follow_) {
        std::int64_t run_id = 0;
        if (PeekRunAndStep(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size, &run_id, &k) &&
            run_id == id_.run_id && k >= 0) {
          BeforeFollowInput(channel, k);
          if (finished()) return;
        }
      }
      const Put put = boxes->Add(channel, rbuf, id_.run_id, &k);
      Count(channel, put, k);
      if (put == Put::kNew) on_new(channel, k, rbuf);
    }, role.wake[c]);
  }
}

void Participant::Attach(Channels* channels) {
  if (lcm_) throw std::runtime_error(name_ + ": Attach: already subscribed on an LCM instance");
  channels_ = channels;
  for (auto& r : routes_) {
    if (!channels_->Subscribe(r->channel.c_str(), &Route::OnChannelMessage, r.get(), r->wake)) {
      throw std::runtime_error(fmt::format("{}: {}", name_, channels_->error()));
    }
  }
}

int Participant::Send(const char* channel, const std::uint8_t* data, std::size_t size) {
  if (channels_) return channels_->Publish(channel, data, static_cast<unsigned int>(size));
  if (!lcm_) return -1;  // neither on an LCM instance nor attached
  return lcm_->publish(channel, data, static_cast<unsigned int>(size));
}

void Participant::SetAnswerChannel(Channel channel, const AnswerCache* cache) {
  answer_channel_ = channel;
  answer_cache_ = cache;
}

void Participant::Deliver(Route* route, const lcm::ReceiveBuffer* rbuf) {
  if (finished_) return;
  const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
  const auto fate = injector_.Decide(route->channel, data, rbuf->data_size, &stats_.injected);
  // The time only matters to faults (a clock read per delivery is a tenth of a memq step).
  const auto now = injector_.active() ? SteadyClock::now() : SteadyClock::time_point{};
  switch (fate) {
    case FaultInjector::Fate::kDrop:
      return;
    case FaultInjector::Fate::kDelay:
    case FaultInjector::Fate::kReorder:
      // A reordered message waits for the next one (or, if none comes, a random delay).
      if (injector_.Hold(route, data, rbuf->data_size, rbuf->recv_utime, injector_.DelayedDue(now),
                         fate == FaultInjector::Fate::kReorder)) {
        return;
      }
      break;
    case FaultInjector::Fate::kDuplicate:
      injector_.Hold(route, data, rbuf->data_size, rbuf->recv_utime, injector_.DelayedDue(now), false);
      break;
    case FaultInjector::Fate::kDeliver:
      break;
  }
  DeliverNow(route, rbuf);
  // A reordered message goes in right after the next one.
  if (injector_.active()) {
    injector_.Release(now, true, [](void* r, const std::uint8_t* d, std::size_t n, std::int64_t utime) {
      lcm::ReceiveBuffer b{const_cast<std::uint8_t*>(d), static_cast<std::uint32_t>(n), utime};
      auto* held_route = static_cast<Route*>(r);
      held_route->self->DeliverNow(held_route, &b);
    });
  }
}

void Participant::DeliverNow(Route* route, const lcm::ReceiveBuffer* rbuf) {
  if (finished_) return;
  if (follow_) {  // any message counts as the feed being alive
    last_clock_ = SteadyClock::now();
    follow_heard_ = true;
  }
  if (!is_clock_ && route->step_evidence != Route::kNothing) {
    // Only the clock publishes desired_t: it is alive, and it has sent GO (a lost GO is
    // repaired here: the first message of a step of our run starts us). A participant that
    // does not read desired_t (the plant, unless it is "ideal") learns the same from the first
    // command_t, current_t or measured_t of a step it had not seen: the clock requested it.
    std::int64_t run_id = 0, k = 0;
    if (PeekRunAndStep(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size, &run_id, &k) &&
        run_id == id_.run_id) {
      if (route->step_evidence == Route::kNextState) --k;
      const bool request = route->step_evidence == Route::kRequest;
      if (request || k > last_clock_step_) {
        // The event loop's next Tick stamps it (a clock read per delivery was 2 % of a memq
        // step); a follower has stamped it above.
        heard_clock_ = !follow_;
        last_clock_step_ = std::max(last_clock_step_, k);
        if (request && !lingering_) StartRunning();
      }
    }
  }
  route->handler(rbuf);
}

void Participant::Tick(SteadyClock::time_point now, bool idle) {
  if (finished_) return;
  if (heard_clock_) {  // the clock's step messages handled since the last Tick: heard by `now`
    last_clock_ = now;
    heard_clock_ = false;
  }
  if (injector_.active()) {
    injector_.Release(now, false, [](void* r, const std::uint8_t* d, std::size_t n, std::int64_t utime) {
      lcm::ReceiveBuffer b{const_cast<std::uint8_t*>(d), static_cast<std::uint32_t>(n), utime};
      auto* held_route = static_cast<Route*>(r);
      held_route->self->DeliverNow(held_route, &b);
    });
  }
  if (!finished_) Poll(now, idle);
}

SteadyClock::time_point Participant::NextDeadline() const {
  if (finished_) return SteadyClock::time_point::max();
  return std::min(injector_.active() ? injector_.NextDue() : SteadyClock::time_point::max(), PollDeadline());
}

void Participant::PublishBytes(const char* channel, const Bytes& bytes) {
  if (Send(channel, bytes.data(), bytes.size()) != 0) {
    Fail(kExitLockstep, fmt::format("could not publish on {}", channel), false);
  }
}

void Participant::Count(Channel channel, Put put, std::int64_t k) {
  switch (put) {
    case Put::kDuplicate: ++stats_.duplicates; return;
    case Put::kStale: ++stats_.stale; return;
    case Put::kForeign: ++stats_.foreign; return;
    case Put::kBad: return;
    case Put::kNew: break;
  }
  for (auto& a : asked_) {
    if (a.first == channel && a.second == k) {
      ++stats_.repaired;
      a = {kNoChannel, -1};
    }
  }
}

void Participant::SendRepair(std::int64_t k, const WantList& wants) {
  repair_out_.run_id = id_.run_id;
  repair_out_.k = k;
  repair_out_.participant = name_;
  repair_out_.n_want = wants.size();
  repair_out_.want_channel.resize(wants.size());
  repair_out_.want_k.resize(wants.size());
  for (int i = 0; i < wants.size(); ++i) {
    repair_out_.want_channel[i] = wants.channel(i);
    repair_out_.want_k[i] = wants.k(i);
    bool known = false;
    for (const auto& a : asked_) known = known || (a.first == wants.channel(i) && a.second == wants.k(i));
    if (!known) {
      asked_[asked_next_] = {wants.channel(i), wants.k(i)};
      asked_next_ = (asked_next_ + 1) % static_cast<int>(asked_.size());
    }
  }
  Encode(repair_out_, &repair_bytes_);
  ++(is_clock_ ? stats_.rerequests : stats_.repair_requests);
  PublishBytes(kChRepair, repair_bytes_);
}

void Participant::SendHandshake(Phase phase, std::int64_t k, const std::string& reason,
                                const std::vector<std::string>* roster) {
  hs_out_.run_id = id_.run_id;
  hs_out_.phase = phase;
  hs_out_.participant = name_;
  hs_out_.scenario_sha256 = id_.scenario_sha256;
  hs_out_.n_steps = id_.n_steps;
  hs_out_.dt_s = id_.dt_s;
  hs_out_.k = k;
  hs_out_.roster_names.clear();
  hs_out_.roster_sha256.clear();
  if (roster) {
    hs_out_.roster_names = *roster;
    hs_out_.roster_sha256.assign(roster->size(), id_.scenario_sha256);
  }
  hs_out_.n_roster = static_cast<std::int32_t>(hs_out_.roster_names.size());
  hs_out_.reason = reason;
  // On the clock's host: the clock watches our process (PeerWatch); else our heartbeats, if any.
  hs_out_.pid = phase == kHello && timing_.announce_pid ? static_cast<std::int32_t>(::getpid()) : 0;
  hs_out_.heartbeat_s = phase == kHello ? timing_.heartbeat_s : 0;
  if (phase == kHello && !said_hello_) {
    said_hello_ = true;
    last_beat_ = SteadyClock::now();
  }
  Encode(hs_out_, &hs_bytes_);
  const int copies = (phase == kAbort || phase == kGo || phase == kClose) ? kControlCopies : 1;
  for (int i = 0; i < copies; ++i) {
    Send(kChHandshake, hs_bytes_.data(), hs_bytes_.size());
  }
}

void Participant::Follow(const FollowOptions& o) {
  follow_ = true;
  follow_idle_s_ = o.idle_exit_s;
  follow_start_s_ = o.start_wait_s;
  for (auto& r : routes_) {
    if (r->subscription) r->subscription->setQueueCapacity(o.queue_capacity);
  }
  OnFollowStart();
  last_clock_ = SteadyClock::now();
  StartRunning();
}

void Participant::StartRunning() {
  if (running_ || finished_) return;
  running_ = true;
  OnGo();
}

void Participant::OnHandshake(const lcm::ReceiveBuffer* rbuf) {
  if (finished_) return;
  if (hs_in_.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
  if (hs_in_.run_id != id_.run_id) {
    ++stats_.foreign;
    return;
  }
  OnHandshakeSeen(rbuf, hs_in_);
  if (finished_) return;
  if (hs_in_.participant == name_) return;  // our own message, looped back
  const auto now = SteadyClock::now();
  if (hs_in_.phase == kAbort) {
    StopOnAbortFrom(hs_in_.participant, hs_in_.reason, hs_in_.k);
    return;
  }
  if (is_clock_) {
    OnHandshakeForClock(hs_in_, now);
    return;
  }
  if (hs_in_.participant != kClockRole) return;
  HeardClock(now);
  switch (hs_in_.phase) {
    case kRequest:
      if (!running_) SendHandshake(kHello);
      break;
    case kGo:
      StartRunning();
      break;
    case kDone:
      if (!lingering_) {
        if (const std::string why = OnDone(); !why.empty()) {
          Fail(kExitOutput, why, true, hs_in_.k);
          return;
        }
        lingering_ = true;
        linger_since_ = now;
        running_ = false;
      }
      SendHandshake(kBye, hs_in_.k);  // again for every repeated DONE: our BYE may have been lost
      break;
    case kClose:
      if (lingering_) Finish();
      break;
    default:
      break;
  }
}

void Participant::OnRepair(const lcm::ReceiveBuffer* rbuf) {
  if (finished_) return;
  if (repair_in_.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
  if (repair_in_.run_id != id_.run_id) {
    ++stats_.foreign;
    return;
  }
  if (repair_in_.participant == name_) return;
  const bool from_clock = repair_in_.participant == kClockRole;
  if (from_clock && !is_clock_) {
    HeardClock(SteadyClock::now());
    if (!lingering_) StartRunning();  // GO was lost: the clock is running step k already
  }
  // Re-send what is wanted of ours, byte for byte from the cache (never recomputed).
  if (answer_cache_ && !Stalled(repair_in_.k)) {
    for (int i = 0; i < repair_in_.n_want; ++i) {
      if (repair_in_.want_channel[i] != answer_channel_) continue;
      if (const Bytes* b = answer_cache_->Get(repair_in_.want_k[i])) {
        PublishBytes(ChannelName(answer_channel_), *b);
        ++stats_.resent;
      }
    }
  }
  if (is_clock_) {
    OnRepairForClock(repair_in_);
    return;
  }
  // The clock re-requests step k: say what we lack to get there.
  if (from_clock && running() && !Stalled(repair_in_.k)) {
    WantList wants;
    Lacks(repair_in_.k, &wants);
    if (!wants.empty()) SendRepair(repair_in_.k, wants);
  }
}

void Participant::Poll(SteadyClock::time_point now, bool idle) {
  if (finished_ || is_clock_) return;
  if (said_hello_ && timing_.heartbeat_s > 0 && SecondsBetween(last_beat_, now) >= timing_.heartbeat_s) {
    last_beat_ = now;
    SendHandshake(kHeartbeat);
  }
  if (lingering_) {
    if (SecondsBetween(linger_since_, now) > timing_.LingerS()) Finish();  // CLOSE was lost
    return;
  }
  if (!idle) return;  // judge silence only once every waiting message has been handled
  if (follow_) {
    if (running_ && SecondsBetween(last_clock_, now) > (follow_heard_ ? follow_idle_s_ : follow_start_s_)) {
      OnFollowEnd();
      Finish();
    }
    return;
  }
  if (!running_) {
    // While the clock keeps asking (REQUEST every 100 ms) it is alive and judges the handshake
    // itself (it names who did not say HELLO); give up only on a clock silent for the whole
    // handshake timeout.
    const SteadyClock::time_point since = std::max(created_, last_clock_);
    if (SecondsBetween(since, now) > timing_.handshake_timeout_s) {
      Fail(kExitLockstep,
           fmt::format("no GO from the clock (integrator): nothing heard from it for {:g} s; is it running "
                       "on the same LCM URL and run id?",
                       timing_.handshake_timeout_s),
           false, -1, std::string(kClockRole));
    }
    return;
  }
  if (SecondsBetween(last_clock_, now) > timing_.WatchdogS()) {
    OnStop();
    Fail(kExitLockstep,
         fmt::format("step {}: the clock (integrator) stopped answering: silent for {:.3g} s", last_clock_step_,
                     SecondsBetween(last_clock_, now)),
         true, last_clock_step_, std::string(kClockRole));
  }
}

void Participant::Fail(int exit_code, const std::string& reason, bool broadcast, std::int64_t k,
                       const std::string& culprit) {
  if (finished_) return;
  if (broadcast) SendHandshake(kAbort, k, reason);
  finished_ = true;
  running_ = false;
  exit_code_ = exit_code;
  error_ = reason;
  culprit_ = culprit;
  fail_step_ = k;
}

void Participant::RelayAbort(const std::string& sender, const std::string& reason, std::int64_t k) {
  if (finished_) return;
  const Bytes bytes = EncodeAbort(id_.run_id, sender, reason, k);
  for (int i = 0; i < kControlCopies; ++i) Send(kChHandshake, bytes.data(), bytes.size());
  StopOnAbortFrom(sender, reason, k);
}

void Participant::StopOnAbortFrom(const std::string& sender, const std::string& reason, std::int64_t k) {
  OnAbortFrom(sender, reason);
  OnStop();
  Fail(kExitPeerAbort, fmt::format("{} aborted the run: {}", sender, reason), false, k);
}

void Participant::MaybeFault(std::int64_t k) {
  if (faults_.process == ProcessFault::kNone || k != faults_.at_step || fault_fired_) return;
  fault_fired_ = true;
  switch (faults_.process) {
    case ProcessFault::kThrow:
      throw std::runtime_error("injected fault ([faults.process] kind = \"throw\")");
    case ProcessFault::kCrash:
      std::abort();
    case ProcessFault::kKill:
      ::raise(SIGKILL);
      break;
    case ProcessFault::kStop:
      if (faults_.stop_s > 0) {
        // A helper process continues us after stop_s, as `kill -CONT` from outside would.
        const pid_t self = ::getpid();
        if (::fork() == 0) {
          ::usleep(static_cast<useconds_t>(faults_.stop_s * 1e6));
          ::kill(self, SIGCONT);
          ::_exit(0);
        }
      }
      ::raise(SIGSTOP);
      break;
    default:
      break;
  }
}

void Participant::Finish() {
  finished_ = true;
  running_ = false;
}

void Participant::Interrupt(const std::string& reason) {
  if (finished_) return;
  OnStop();
  Fail(kExitPeerAbort, reason, false);
}

}  // namespace rths::lockstep
