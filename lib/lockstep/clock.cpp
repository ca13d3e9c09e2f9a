#include "lockstep/clock.h"

#include <algorithm>
#include <cstdio>
#include <exception>

#include <fmt/core.h>

#include "lockstep/abort.h"

namespace rths::lockstep {

namespace {
constexpr double kHandshakeRepeatS = 0.1;
/// How long the loss of a participant that exited on an ABORT waits for that ABORT [s].
constexpr double kAbortGraceS = 1.0;

double Seconds(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " and " : ", ";
    out += names[i];
  }
  return out;
}
}  // namespace

ClockParticipant::ClockParticipant(std::string name, RunIdentity id, LockstepConfig config, lcm::LCM* lcm,
                                   const Wiring& wiring, Faults faults)
    : Participant(std::move(name), std::move(id), config, lcm, std::move(faults)), wiring_(wiring) {
  is_clock_ = true;
  hello_.fill(false);
  bye_.fill(false);
  reported_.fill(false);
  const int self = RosterIndex(name_);
  if (self >= 0) {
    hello_[self] = true;
    bye_[self] = true;
  }
  owner_.fill(-1);
  for (int i = 0; i < kRosterSize; ++i) {
    const ResolvedRole& r = wiring_.roles()[i];
    if (!r.row->clock && r.row->answer != kNoChannel) owner_[r.row->answer] = i;
  }
  start_ = SteadyClock::now();
  last_send_ = start_ - std::chrono::seconds(1);
  rt_.paced = timing_.pacing.enabled;
  rt_.period_s = timing_.pacing.period_s;
  if (rt_.paced) rt_.SizeWindows(id_.n_steps, rt_.period_s);
  SetAnswerChannel(kDesired, &desired_cache_);
  const RoleRow& row = *wiring_.Clock().row;
  for (int i = 0; i < row.n_inputs(); ++i) {
    if (row.inputs[i].channel == kMeasured) measured_offset_ = row.inputs[i].offset;
  }
  if (measured_offset_ > 0) throw std::runtime_error(name_ + ": the clock cannot wait for a later measured_t");
  // The barrier of step k is the clock's inputs of step k+1 (wiring.h); only the last of them to
  // be sent (ack_t: the logger acknowledges step k once it holds the rest) wakes the clock.
  SubscribeInputs(wiring_.Clock(), &boxes_, [this](Channel channel, std::int64_t k, const lcm::ReceiveBuffer*) {
    if (k_ >= 0 && wiring_.Clock().Waits(channel, k, k_ + 1)) CheckBarrier();
    if (awaiting_first_ && channel == kMeasured && k == 0) IssueFirst();
  });
}

void ClockParticipant::OnHandshakeForClock(const rths::handshake_t& msg, SteadyClock::time_point now) {
  const int i = RosterIndex(msg.participant);
  if (i < 0) {
    std::fprintf(stderr, "%s: ignoring handshake from unknown participant '%s'\n", name_.c_str(),
                 msg.participant.c_str());
    return;
  }
  if (msg.phase == kHello && k_ < 0 && !hello_[i]) {
    if (msg.scenario_sha256 != id_.scenario_sha256) {
      Fail(kExitLockstep,
           fmt::format("scenario mismatch: {} loaded a scenario with SHA-256 {}, {} loaded {}",
                       msg.participant, msg.scenario_sha256, name_, id_.scenario_sha256),
           true, -1, msg.participant);
      return;
    }
    if (msg.n_steps != id_.n_steps || msg.dt_s != id_.dt_s) {
      Fail(kExitLockstep,
           fmt::format("{} expects {} steps of {} s, {} expects {} steps of {} s", msg.participant,
                       msg.n_steps, msg.dt_s, name_, id_.n_steps, id_.dt_s),
           true, -1, msg.participant);
      return;
    }
    hello_[i] = true;
    peers_[i].hello = true;
    peers_[i].pid = msg.pid;
    peers_[i].heartbeat_s = msg.heartbeat_s;
    watch_.Watch(i, msg.pid, msg.heartbeat_s, now);
    bool all = true;
    for (bool h : hello_) all = all && h;
    if (all) SendGo();
  } else if (msg.phase == kHeartbeat) {
    watch_.Beat(i, now);
  } else if (msg.phase == kBye && done_) {
    bye_[i] = true;
    peers_[i].bye = true;
    watch_.Forget(i);  // it may exit now
    bool all = true;
    for (bool b : bye_) all = all && b;
    if (all) {
      SendHandshake(kClose, id_.n_steps);
      live_.Phase(kLiveCompleted, live_sink_);
      Finish();
    }
  }
}

void ClockParticipant::OnRepairForClock(const rths::repair_t& msg) {
  const int i = RosterIndex(msg.participant);
  if (i < 0) return;
  ++peers_[i].repair_requests;
  if (msg.k == k_) reported_[i] = true;
}

void ClockParticipant::Count(Channel channel, Put put, std::int64_t k) {
  Participant::Count(channel, put, k);
  const int owner = owner_[channel];
  if (owner < 0) return;
  if (put == Put::kNew) ++peers_[owner].answers;
  if (put == Put::kDuplicate) ++peers_[owner].duplicates;
}

void ClockParticipant::OnAbortFrom(const std::string& participant, const std::string& reason) {
  const int i = RosterIndex(participant);
  if (i < 0) return;
  peers_[i].aborted = true;
  peers_[i].abort_reason = reason;
}

void ClockParticipant::FailLost(const PeerLoss& loss) {
  PeerObservation& p = peers_[loss.role];
  p.lost = true;
  p.loss = loss;
  const std::string role(kRoster[loss.role]);
  const std::string where = k_ < 0 ? "before step 0" : fmt::format("at step {}", k_);
  OnStop();
  Fail(kExitLockstep, fmt::format("{} was lost {}: {}", role, where, loss.what), true, k_, role);
}

void ClockParticipant::Lacks(std::int64_t k, WantList* out) const {
  const ResolvedRole& clock = wiring_.Clock();
  for (int i = 0; i < clock.n_waits; ++i) {
    const std::int64_t j = k + 1 + clock.waits[i].offset;
    if (Exists(j) && !boxes_.Has(clock.waits[i].channel, j)) out->Add(clock.waits[i].channel, j);
  }
}

bool ClockParticipant::Answered(const ResolvedRole& role) const {
  for (int b = 0; b < role.row->n_barrier; ++b) {
    const std::int64_t j = k_ + role.row->barrier[b];
    if (Exists(j) && !boxes_.Has(role.row->answer, j)) return false;
  }
  return true;
}

void ClockParticipant::SendGo() {
  std::vector<std::string> roster;
  for (std::string_view r : kRoster) roster.emplace_back(r);
  SendHandshake(kGo, 0, "", &roster);  // several copies; a lost GO is also repaired by step 0
  go_at_ = SteadyClock::now();
  live_.Start(id_.run_id, id_.n_steps, id_.dt_s, rt_.paced, live_limits_);
  live_.Phase(kLiveRunning, live_sink_);
  OnGo();
  if (measured_offset_ == 0 && !boxes_.measured.Get(0)) {
    awaiting_first_ = true;
    last_send_ = go_at_;
    return;
  }
  IssueFirst();
}

void ClockParticipant::IssueFirst() {
  awaiting_first_ = false;
  rerequests_ = 0;
  go_at_ = SteadyClock::now();
  try {
    IssueStep(0);
  } catch (const std::exception& e) {
    Fail(kExitInternal, fmt::format("{}: step 0: {}", name_, e.what()), true, 0);
  }
}

void ClockParticipant::PollFirst(SteadyClock::time_point now, bool idle) {
  if (boxes_.measured.Get(0)) {
    IssueFirst();
    return;
  }
  const int plant = owner_[kMeasured];
  const std::string who = plant >= 0 ? std::string(kRoster[plant]) : std::string("plant");
  if (idle && Seconds(go_at_, now) > timing_.stall_budget_s) {
    Fail(kExitLockstep,
         fmt::format("before step 0: {} stopped answering: no measured_t 0 after {:.3g} s and {} re-requests", who,
                     Seconds(go_at_, now), rerequests_),
         true, -1, who);
    return;
  }
  if (Seconds(last_send_, now) < timing_.RerequestAfterS(rerequests_ + 1, typical_step_s_)) return;
  if (rerequests_ == 0) ++stats_.steps_rerequested;
  ++rerequests_;
  last_send_ = now;
  if (plant >= 0) ++peers_[plant].rerequests;
  WantList wants;
  wants.Add(kMeasured, 0);
  SendRepair(0, wants);
}

SteadyClock::time_point ClockParticipant::ReleaseOf(std::int64_t k) const {
  return go_at_ + std::chrono::duration_cast<SteadyClock::duration>(
                      std::chrono::duration<double>(static_cast<double>(k) * timing_.pacing.period_s));
}

bool ClockParticipant::AccountStep(SteadyClock::time_point now) {
  const double latency_s = Seconds(step_since_, now);
  rt_.latency.Add(latency_s);
  ++rt_.steps;
  if (!rt_.paced) return true;
  rt_.AddToWindow(k_, latency_s, now > ReleaseOf(k_ + 1));
  if (now > ReleaseOf(k_ + 1)) {
    ++rt_.misses;
    if (rt_.first_miss_step < 0) rt_.first_miss_step = k_;
    rt_.max_consecutive_misses = std::max(rt_.max_consecutive_misses, ++consecutive_misses_);
    const std::int64_t limit = timing_.pacing.max_consecutive_misses;
    if (limit > 0 && consecutive_misses_ >= limit) {
      // Where the time went: a step issued late (the host woke the clock late, or the previous
      // step ran over) misses its deadline however fast it runs.
      const double late_ms = 1e3 * Seconds(ReleaseOf(k_ + 1), now);
      const double issued_late_ms = 1e3 * std::max(0.0, Seconds(ReleaseOf(k_), step_since_));
      Fail(kExitRealtime,
           fmt::format("step {}: {} consecutive deadline misses (realtime.max_consecutive_misses = {}): the step ended "
                       "{:.3g} ms after its deadline; it was issued {:.3g} ms after its release and took {:.3g} ms "
                       "(period {:.3g} ms); {} of {} steps missed so far",
                       k_, consecutive_misses_, limit, late_ms, issued_late_ms, 1e3 * Seconds(step_since_, now),
                       1e3 * rt_.period_s, rt_.misses, rt_.steps),
           true, k_);
      return false;
    }
  } else {
    consecutive_misses_ = 0;
  }
  return true;
}

void ClockParticipant::IssueStep(std::int64_t k) {
  MaybeFault(k);
  const std::int64_t j = k + measured_offset_;
  const rths::measured_t* measured = j >= 0 ? boxes_.measured.Get(j) : nullptr;
  ComputeDesired(k, measured, &desired_);
  desired_.run_id = id_.run_id;
  desired_.k = k;
  k_ = k;
  rerequests_ = 0;
  reported_.fill(false);
  step_since_ = last_send_ = SteadyClock::now();
  if (rt_.paced) rt_.max_release_late_s = std::max(rt_.max_release_late_s, Seconds(ReleaseOf(k), step_since_));
  Answer(kChDesired, &desired_cache_, k, desired_);
}

void ClockParticipant::CheckBarrier() {
  if (finished() || done_ || k_ < 0 || Stalled(k_)) return;
  WantList lacks;
  Lacks(k_, &lacks);
  if (!lacks.empty()) return;
  const rths::measured_t* m = boxes_.measured.Get(k_);
  const rths::command_t* c = boxes_.command.Get(k_);
  if (!m || !c) return;  // every table has them in the barrier (safety check)
  const auto now = SteadyClock::now();
  if (rerequests_ == 0) {
    // How long a step takes when nothing is lost (a moving average over ~16 steps): it sets how
    // soon a silence counts as a loss.
    const double took_s = Seconds(step_since_, now);
    typical_step_s_ = typical_step_s_ > 0 ? typical_step_s_ + (took_s - typical_step_s_) / 16.0 : took_s;
  }
  stepping_s_ = Seconds(go_at_, now);
  if (const std::string_view stop = CheckCommitted(k_, desired_, *m, *c); !stop.empty()) {
    Fail(kExitSafety, std::string(stop), true, k_);
    return;
  }
  const bool missed = rt_.paced && now > ReleaseOf(k_ + 1);
  if (!AccountStep(now)) {
    live_.Phase(kLiveAborted, live_sink_);
    return;
  }
  if (live_sink_) {
    if (const int n = std::min({desired_.n_act, c->n_act, m->n_act}); n > 0) {
      live_.KeepActuatorPeaks(n, desired_.r_act_mm.data(), c->u_act_mm.data(), m->y_act_mm.data());
    }
    live_.Add(k_, desired_.r_mm, c->u_mm, m->y_mm, m->f_kN, m->current_A, Seconds(step_since_, now), missed, rt_,
              live_sink_);
  }
  if (k_ + 1 >= id_.n_steps) {
    live_.Phase(kLiveFinishing, live_sink_);
    done_ = true;
    rerequests_ = 0;
    step_since_ = last_send_ = SteadyClock::now();
    SendHandshake(kDone, id_.n_steps);
    return;
  }
  if (rt_.paced && now < ReleaseOf(k_ + 1)) {
    release_ = ReleaseOf(k_ + 1);  // Poll() issues it when the event loop wakes up at the release
    return;
  }
  IssueNext();
}

void ClockParticipant::IssueNext() {
  try {
    IssueStep(k_ + 1);
  } catch (const std::exception& e) {
    Fail(kExitInternal, fmt::format("{}: step {}: {}", name_, k_ + 1, e.what()), true, k_ + 1);
  }
}

void ClockParticipant::FailStalled(SteadyClock::time_point now) {
  // Silent: its answer of step k is missing and it never said what it lacked. Waiting: its
  // answer is missing but it asked for inputs (alive; it waits for a silent one).
  std::vector<std::string> silent, waiting;
  for (int i = 0; i < kRosterSize; ++i) {
    const ResolvedRole& r = wiring_.roles()[i];
    if (r.row->clock || Answered(r)) continue;
    (reported_[i] ? waiting : silent).emplace_back(r.role());
  }
  if (silent.empty()) {
    // Every one that lacks its answer says it is waiting: blame the first in the step's order
    // (the plant's measurement feeds everyone, then the controller and semiactive, then the logger).
    for (int i : wiring_.step_order()) {
      if (!Answered(wiring_.roles()[i])) {
        silent.emplace_back(kRoster[i]);
        break;
      }
    }
    std::erase(waiting, silent.front());
  }
  // A lone silent role that gave its answer of step k but not a later one the barrier holds (the
  // plant's measured_t k+1): name the message.
  std::string missing = "no answer";
  if (silent.size() == 1) {
    const ResolvedRole& r = wiring_.Of(silent.front());
    for (int b = 0; b < r.row->n_barrier; ++b) {
      const std::int64_t j = k_ + r.row->barrier[b];
      if (!Exists(j) || boxes_.Has(r.row->answer, j)) continue;
      if (r.row->barrier[b] != 0) missing = fmt::format("no {} {}", MessageName(r.row->answer), j);
      break;
    }
  }
  std::string reason = fmt::format("step {}: {} stopped answering: {} after {:.3g} s and {} re-requests", k_,
                                   JoinNames(silent), missing, Seconds(step_since_, now), rerequests_);
  if (!waiting.empty()) reason += fmt::format(" ({} only waited for it)", JoinNames(waiting));
  if (silent.size() == 1) {
    const PeerObservation& p = peers_[RosterIndex(silent.front())];
    if (p.pid == 0 && p.heartbeat_s <= 0) {
      reason += fmt::format("; it gave neither its pid nor a heartbeat period in its HELLO, so only the stall budget "
                            "(lockstep.stall_budget_s = {:g} s) could tell it was gone (docs/participant.md, "
                            "\"Liveness\")",
                            timing_.stall_budget_s);
    }
  }
  Fail(kExitLockstep, reason, true, k_, silent.size() == 1 ? silent.front() : JoinNames(silent));
}

SteadyClock::time_point ClockParticipant::PollDeadline() const {
  if (release_ != SteadyClock::time_point::max()) return release_;
  if (!awaiting_first_ && (k_ < 0 || Stalled(k_))) return SteadyClock::time_point::max();
  return last_send_ + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(
                          timing_.RerequestAfterS(rerequests_ + 1, typical_step_s_)));
}

void ClockParticipant::PublishLive() {
  publish_sink_ = std::make_unique<PublishSink>(this);
  live_sink_ = publish_sink_.get();
}

void ClockParticipant::PublishSink::Push(const rths::monitor_t& record) {
  Encode(record, &bytes_);
  clock_->PublishBytes(kChMonitor, bytes_);
}

void ClockParticipant::Poll(SteadyClock::time_point now, bool idle) {
  if (finished()) return;
  if (std::string reason; live_sink_ && live_sink_->TakeAbort(&reason)) {
    // The operator pressed ABORT on a monitor in this process: as if "monitor" had sent it.
    live_.Phase(kLiveAborted, live_sink_);
    RelayAbort(kMonitorSender, reason, k_);
    return;
  }
  if (!done_) {
    if (pending_loss_ && now >= pending_loss_until_) {  // the ABORT it stopped on never came
      FailLost(*pending_loss_);
      return;
    }
    if (const std::optional<PeerLoss> loss = watch_.Check(now)) {
      if (loss->died && loss->status_known && loss->exit_code == kExitPeerAbort && !pending_loss_) {
        pending_loss_ = loss;
        pending_loss_until_ = now + std::chrono::duration_cast<SteadyClock::duration>(
                                        std::chrono::duration<double>(kAbortGraceS));
      } else {
        FailLost(*loss);
        return;
      }
    }
  }
  if (awaiting_first_) {
    PollFirst(now, idle);
    return;
  }
  if (k_ < 0) {
    PollHandshake(now, idle);
    return;
  }
  if (release_ != SteadyClock::time_point::max()) {  // paced: step k_ is complete, k_+1 not yet due
    if (now < release_) return;
    release_ = SteadyClock::time_point::max();
    IssueNext();
    return;
  }
  if (Stalled(k_)) return;
  if (done_) {
    PollDone(now, idle);
    return;
  }
  if (idle && Seconds(step_since_, now) > timing_.stall_budget_s) {
    FailStalled(now);
    return;
  }
  if (Seconds(last_send_, now) < timing_.RerequestAfterS(rerequests_ + 1, typical_step_s_)) return;
  if (rerequests_ == 0) ++stats_.steps_rerequested;
  ++rerequests_;
  last_send_ = now;
  WantList wants;
  Lacks(k_, &wants);
  std::array<bool, kRosterSize> listed{};
  for (int w = 0; w < wants.size(); ++w) {
    const int owner = owner_[wants.channel(w)];
    if (owner >= 0 && !listed[owner]) ++peers_[owner].rerequests;
    if (owner >= 0) listed[owner] = true;
  }
  SendRepair(k_, wants);
}

void ClockParticipant::PollHandshake(SteadyClock::time_point now, bool idle) {
  if (idle && Seconds(start_, now) > timing_.handshake_timeout_s) {
    std::vector<std::string> missing;
    for (int i = 0; i < kRosterSize; ++i) {
      if (!hello_[i]) missing.emplace_back(kRoster[i]);
    }
    Fail(kExitLockstep,
         fmt::format("no HELLO from {} within {:g} s: not started, crashed, or on another LCM "
                     "URL / run id",
                     JoinNames(missing), timing_.handshake_timeout_s),
         true, -1, missing.size() == 1 ? missing.front() : JoinNames(missing));
    return;
  }
  if (Seconds(last_send_, now) >= kHandshakeRepeatS) {
    SendHandshake(kRequest);
    last_send_ = now;
  }
}

void ClockParticipant::PollDone(SteadyClock::time_point now, bool idle) {
  if (idle && Seconds(step_since_, now) > timing_.stall_budget_s) {
    std::vector<std::string> missing;
    for (int i = 0; i < kRosterSize; ++i) {
      if (!bye_[i]) missing.emplace_back(kRoster[i]);
    }
    std::fprintf(stderr, "%s: every step committed, but no BYE from %s within %g s\n", name_.c_str(),
                 JoinNames(missing).c_str(), timing_.stall_budget_s);
    SendHandshake(kClose, id_.n_steps);
    live_.Phase(kLiveCompleted, live_sink_);
    Finish();
    return;
  }
  if (Seconds(last_send_, now) >= timing_.RerequestAfterS(rerequests_ + 1, typical_step_s_)) {
    ++rerequests_;
    last_send_ = now;
    SendHandshake(kDone, id_.n_steps);
  }
}

}  // namespace rths::lockstep
