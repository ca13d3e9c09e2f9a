#include "lockstep/clock.h"

#include <cstdio>
#include <exception>

#include <fmt/core.h>

namespace rths::lockstep {

namespace {
constexpr double kHandshakeRepeatS = 0.1;

double Seconds(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

int RosterIndex(const std::string& name) {
  for (std::size_t i = 0; i < kRoster.size(); ++i) {
    if (name == kRoster[i].name) return static_cast<int>(i);
  }
  return -1;
}
}  // namespace

ClockParticipant::ClockParticipant(std::string name, RunIdentity id, Timing timing, lcm::LCM* lcm)
    : Participant(std::move(name), std::move(id), timing, lcm) {
  is_clock_ = true;
  hello_.fill(false);
  bye_.fill(false);
  const int self = RosterIndex(name_);
  if (self >= 0) {
    hello_[self] = true;
    bye_[self] = true;
  }
  start_ = SteadyClock::now();
  last_send_ = start_ - std::chrono::seconds(1);
  lcm_->subscribe(kChMeasured, &ClockParticipant::OnMeasured, this);
  lcm_->subscribe(kChCommand, &ClockParticipant::OnCommand, this);
  lcm_->subscribe(kChCurrent, &ClockParticipant::OnCurrent, this);
  lcm_->subscribe(kChAck, &ClockParticipant::OnAck, this);
}

void ClockParticipant::OnHandshakeForClock(const rths::handshake_t& msg, SteadyClock::time_point) {
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
           true);
      return;
    }
    if (msg.n_steps != id_.n_steps || msg.dt_s != id_.dt_s) {
      Fail(kExitLockstep,
           fmt::format("{} expects {} steps of {} s, {} expects {} steps of {} s", msg.participant,
                       msg.n_steps, msg.dt_s, name_, id_.n_steps, id_.dt_s),
           true);
      return;
    }
    hello_[i] = true;
    bool all = true;
    for (bool h : hello_) all = all && h;
    if (all) SendGo();
  } else if (msg.phase == kBye) {
    bye_[i] = true;
    bool all = true;
    for (bool b : bye_) all = all && b;
    if (all && done_) Finish();
  }
}

void ClockParticipant::SendGo() {
  std::vector<std::string> roster;
  for (const auto& r : kRoster) roster.emplace_back(r.name);
  // GO is sent twice: a participant that missed it would otherwise wait for the watchdog.
  SendHandshake(kGo, 0, "", &roster);
  SendHandshake(kGo, 0, "", &roster);
  OnGo();
  try {
    IssueStep(0);
  } catch (const std::exception& e) {
    Fail(kExitInternal, fmt::format("{}: step 0: {}", name_, e.what()), true, 0);
  }
}

void ClockParticipant::IssueStep(std::int64_t k) {
  const rths::measured_t* prev = k > 0 ? measured_.Get(k - 1) : nullptr;
  ComputeDesired(k, prev, &desired_);
  desired_.run_id = id_.run_id;
  desired_.k = k;
  k_ = k;
  attempts_ = 1;
  last_send_ = SteadyClock::now();
  Answer(kChDesired, &desired_cache_, k, desired_);
}

void ClockParticipant::CheckBarrier() {
  if (finished() || done_ || k_ < 0) return;
  const rths::measured_t* m = measured_.Get(k_);
  const rths::command_t* c = command_.Get(k_);
  if (!m || !c || !current_.Get(k_) || !ack_.Get(k_)) return;
  if (const std::string_view stop = CheckCommitted(k_, desired_, *m, *c); !stop.empty()) {
    Fail(kExitSafety, std::string(stop), true, k_);
    return;
  }
  if (k_ + 1 >= id_.n_steps) {
    done_ = true;
    done_sends_ = 1;
    last_send_ = SteadyClock::now();
    SendHandshake(kDone, id_.n_steps);
    return;
  }
  try {
    IssueStep(k_ + 1);
  } catch (const std::exception& e) {
    Fail(kExitInternal, fmt::format("{}: step {}: {}", name_, k_ + 1, e.what()), true, k_ + 1);
  }
}

#define RTHS_CLOCK_HANDLER(Method, box)                                                   \
  void ClockParticipant::Method(const lcm::ReceiveBuffer* rbuf, const std::string&) {     \
    if (finished()) return;                                                               \
    if (box.Add(rbuf, id_.run_id) == std::remove_reference_t<decltype(box)>::Put::kNew && \
        box.last_k() == k_)                                                               \
      CheckBarrier();                                                                     \
  }
RTHS_CLOCK_HANDLER(OnMeasured, measured_)
RTHS_CLOCK_HANDLER(OnCommand, command_)
RTHS_CLOCK_HANDLER(OnCurrent, current_)
RTHS_CLOCK_HANDLER(OnAck, ack_)
#undef RTHS_CLOCK_HANDLER

std::string ClockParticipant::MissingAnswers(std::int64_t k) const {
  // Who is silent, and who only waits for them: the controller and the semiactive law need
  // measured_t k; the logger needs everything; the plant's inputs (step k-1) are all in.
  const bool m = measured_.Get(k) != nullptr, c = command_.Get(k) != nullptr,
             i = current_.Get(k) != nullptr, a = ack_.Get(k) != nullptr;
  std::string silent, waiting;
  auto add = [](std::string* list, const char* text) {
    if (!list->empty()) *list += ", ";
    *list += text;
  };
  if (!m) add(&silent, "plant (measured_t)");
  if (!c) add(m ? &silent : &waiting, "controller (command_t)");
  if (!i) add(m ? &silent : &waiting, "semiactive (current_t)");
  if (!a) add(m && c && i ? &silent : &waiting, "logger (ack_t)");
  return waiting.empty() ? silent : fmt::format("{} (also missing, waiting for it: {})", silent, waiting);
}

void ClockParticipant::Poll(SteadyClock::time_point now) {
  if (finished()) return;
  const double timeout_s = timing_.timeout_ms * 1e-3;
  if (k_ < 0) {  // handshake
    if (Seconds(start_, now) > timing_.handshake_timeout_s) {
      std::string missing;
      for (std::size_t i = 0; i < kRoster.size(); ++i) {
        if (hello_[i]) continue;
        if (!missing.empty()) missing += ", ";
        missing += kRoster[i].name;
      }
      Fail(kExitLockstep,
           fmt::format("no HELLO from {} within {:g} s: not started, crashed, or on another LCM "
                       "URL / run id",
                       missing, timing_.handshake_timeout_s),
           true);
      return;
    }
    if (Seconds(last_send_, now) >= kHandshakeRepeatS) {
      SendHandshake(kRequest);
      last_send_ = now;
    }
    return;
  }
  if (Seconds(last_send_, now) < timeout_s) return;
  if (done_) {
    if (done_sends_ >= timing_.max_attempts) {
      std::string missing;
      for (std::size_t i = 0; i < kRoster.size(); ++i) {
        if (!bye_[i]) missing += std::string(missing.empty() ? "" : ", ") + kRoster[i].name;
      }
      std::fprintf(stderr, "%s: every step committed, but no BYE from %s\n", name_.c_str(),
                   missing.c_str());
      Finish();
      return;
    }
    SendHandshake(kDone, id_.n_steps);
    ++done_sends_;
    last_send_ = now;
    return;
  }
  if (attempts_ >= timing_.max_attempts) {
    Fail(kExitLockstep,
         fmt::format("step {}: no answer from {} after {} requests over {:.3g} s", k_,
                     MissingAnswers(k_), attempts_, attempts_ * timeout_s),
         true, k_);
    return;
  }
  ++attempts_;
  last_send_ = now;
  Republish(kChDesired, desired_cache_, k_);
}

}  // namespace rths::lockstep
