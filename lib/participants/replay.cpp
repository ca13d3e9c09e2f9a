#include "participants/replay.h"

#include <algorithm>
#include <memory>

#include <fmt/core.h>

#include "core/error.h"
#include "lockstep/clock.h"
#include "lockstep/transport.h"
#include "participants/factory.h"
#include "participants/logger.h"

namespace rths::participants {

namespace {

/// The clock, issuing the recorded desired_t of every step.
class RecordedClock final : public lockstep::ClockParticipant {
 public:
  RecordedClock(const std::vector<rths::desired_t>* record, lockstep::RunIdentity id, lockstep::Timing timing,
                lcm::LCM* lcm)
      : ClockParticipant("integrator", std::move(id), timing, lcm), record_(record) {}

 protected:
  void ComputeDesired(std::int64_t k, const rths::measured_t*, rths::desired_t* out) override {
    *out = (*record_)[static_cast<std::size_t>(k)];  // same sizes every step: no allocation
  }

 private:
  const std::vector<rths::desired_t>* record_;
};

/// A controller, plant or semiactive that answers step k with its recorded message, once the
/// clock has requested step k (desired_t k arrived).
template <class Msg>
class RecordedAnswer final : public lockstep::Participant {
 public:
  RecordedAnswer(std::string role, const std::vector<Msg>* record, lockstep::RunIdentity id, lockstep::Timing timing,
                 lcm::LCM* lcm, const char* channel, lockstep::Channel code)
      : Participant(std::move(role), std::move(id), timing, lcm), record_(record), channel_(channel) {
    SetAnswerChannel(code, &cache_);
    Subscribe(lockstep::kChDesired, [this](const lcm::ReceiveBuffer* rbuf) {
      if (!finished() && Receive(&desired_, lockstep::kDesired, rbuf) == lockstep::Put::kNew) TryStep();
    });
  }

 protected:
  void ListMissing(std::int64_t k, lockstep::WantList* out) const override {
    if (next_ <= k && !desired_.Get(next_)) out->Add(lockstep::kDesired, next_);
  }

 private:
  void TryStep() {
    while (running() && next_ < id_.n_steps && desired_.Get(next_)) {
      answer_ = (*record_)[static_cast<std::size_t>(next_)];
      answer_.run_id = id_.run_id;
      answer_.k = next_;
      Answer(channel_, &cache_, next_, answer_);
      ++next_;
    }
  }

  const std::vector<Msg>* record_;
  const char* const channel_;
  lockstep::StepMailbox<rths::desired_t> desired_;
  lockstep::AnswerCache cache_;
  Msg answer_{};
  std::int64_t next_ = 0;
};

bool IsLive(const std::vector<std::string>& live, std::string_view role) {
  return role == "logger" || std::find(live.begin(), live.end(), role) != live.end();
}

}  // namespace

const char* AnswerChannelOf(std::string_view role) {
  for (const auto& r : lockstep::kRoster) {
    if (role == r.name && role != "logger") return r.channel;
  }
  throw Error("replay", fmt::format("unknown role '{}' (live roles: integrator, controller, plant, semiactive)", role));
}

std::vector<Outcome> RunReplay(const scenario::Scenario& s, const io::RunLog& record, std::int64_t steps,
                               const std::vector<std::string>& live, std::int64_t run_id, const std::string& out_dir,
                               const volatile std::sig_atomic_t* stop) {
  for (const auto& role : live) AnswerChannelOf(role);  // throws for an unknown role
  if (steps <= 0 || steps > record.CompleteSteps()) {
    throw Error(record.source, fmt::format("cannot replay {} steps: the log holds {} complete steps", steps,
                                           record.CompleteSteps()));
  }
  lockstep::InprocChannels bus;
  lockstep::RunIdentity id = IdentityOf(s, run_id);
  id.n_steps = steps;
  const lockstep::Timing timing = TimingOf(s);
  std::vector<std::unique_ptr<lockstep::Participant>> owned;
  for (std::string_view role : kGroupOrder) {
    if (role == "logger") {
      // A recorded plant answers desired_t k with measured_t k: the logger must not wait for
      // measured_t k+1 (Logger, ack_after_next_measured).
      owned.push_back(std::make_unique<Logger>(id, timing, nullptr, out_dir + "/log.lcm", out_dir + "/signals.csv",
                                               lockstep::Faults{}, s.run.csv_every, false));
    } else if (IsLive(live, role)) {
      owned.push_back(MakeParticipant(role, s, id, nullptr, out_dir, {}));
      if (role == "integrator" && !IsLive(live, "plant")) {
        // The recorded plant answers desired_t k with measured_t k: no measured_t k+1 in the barrier.
        static_cast<lockstep::ClockParticipant*>(owned.back().get())->SetBarrierIncludesNextMeasured(false);
      }
    } else if (role == "integrator") {
      owned.push_back(std::make_unique<RecordedClock>(&record.desired, id, timing, nullptr));
    } else if (role == "controller") {
      owned.push_back(std::make_unique<RecordedAnswer<rths::command_t>>(
          "controller", &record.command, id, timing, nullptr, lockstep::kChCommand, lockstep::kCommand));
    } else if (role == "plant") {
      owned.push_back(std::make_unique<RecordedAnswer<rths::measured_t>>(
          "plant", &record.measured, id, timing, nullptr, lockstep::kChMeasured, lockstep::kMeasured));
    } else {
      owned.push_back(std::make_unique<RecordedAnswer<rths::current_t>>(
          "semiactive", &record.current, id, timing, nullptr, lockstep::kChCurrent, lockstep::kCurrent));
    }
  }
  std::vector<lockstep::Participant*> group;
  for (auto& p : owned) group.push_back(p.get());
  for (auto* p : group) p->Attach(&bus);
  lockstep::RunLoop(&bus, group, stop);
  std::vector<Outcome> outcomes;
  for (const auto* p : group) outcomes.push_back(OutcomeOf(*p));
  return outcomes;
}

}  // namespace rths::participants
