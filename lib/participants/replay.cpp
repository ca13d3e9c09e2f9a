#include "participants/replay.h"

#include "core/closest_name.h"

#include "lockstep/bridge.h"

#include <algorithm>
#include <memory>

#include <fmt/format.h>

#include "core/closest_name.h"
#include "core/error.h"
#include "lockstep/clock.h"
#include "lockstep/transport.h"
#include "participants/factory.h"
#include "lockstep/step_participant.h"
#include "lockstep/step_table.h"

namespace rths::participants {

namespace {

/// The clock, issuing the recorded desired_t of every step.
class RecordedClock final : public lockstep::ClockParticipant {
 public:
  RecordedClock(const std::vector<rths::desired_t>* record, lockstep::RunIdentity id,
                lockstep::LockstepConfig config, const lockstep::Wiring& wiring)
      : ClockParticipant("integrator", std::move(id), config, nullptr, wiring), record_(record) {}

 protected:
  void ComputeDesired(std::int64_t k, const rths::measured_t*, rths::desired_t* out) override {
    *out = (*record_)[static_cast<std::size_t>(k)];  // same sizes every step: no allocation
  }

 private:
  const std::vector<rths::desired_t>* record_;
};

/// A controller, plant or semiactive that answers step k with its recorded message, once the
/// clock has requested step k (desired_t k arrived): the role's "recorded" row of the step table.
template <class Msg>
class RecordedAnswer final : public lockstep::StepAnswerer<Msg> {
 public:
  RecordedAnswer(std::string_view role, const std::vector<Msg>* record, lockstep::RunIdentity id,
                 lockstep::LockstepConfig config, const lockstep::Wiring& wiring)
      : lockstep::StepAnswerer<Msg>(std::string(role), std::move(id), config, nullptr, {}, wiring.Of(role)),
        record_(record) {}

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs&, Msg* out) override {
    *out = (*record_)[static_cast<std::size_t>(k)];
    return true;
  }

 private:
  const std::vector<Msg>* record_;
};

bool IsLive(const std::vector<std::string>& live, std::string_view role) {
  return role == "logger" || std::find(live.begin(), live.end(), role) != live.end();
}

}  // namespace

const char* AnswerChannelOf(std::string_view role) {
  std::vector<std::string_view> roles;  // the roles a replay can take live: all but the logger
  for (const lockstep::RoleRow& r : lockstep::kStepTable) {
    if (!r.variant.empty() || r.acks_barrier) continue;
    if (role == r.role) return lockstep::ChannelName(r.answer);
    roles.push_back(r.role);
  }
  const std::string_view close = ClosestName(role, roles);
  throw Error("--live", fmt::format("unknown role '{}'{} (live roles: {})", role,
                                    close.empty() ? "" : fmt::format("; did you mean {}?", close),
                                    fmt::join(roles, ", ")));
}

std::vector<Outcome> RunReplay(const scenario::Scenario& s, const io::RunLog& record, std::int64_t steps,
                               const std::vector<std::string>& live, std::int64_t run_id, const std::string& out_dir,
                               const volatile std::sig_atomic_t* stop, const std::vector<std::string>& external,
                               const std::string& udpm_url) {
  for (const auto& role : live) AnswerChannelOf(role);  // throws for an unknown role
  for (const auto& role : external) {
    if (std::find(live.begin(), live.end(), role) == live.end()) {
      throw Error("--external", fmt::format("{} is not live: an external role must also be named by --live", role));
    }
  }
  if (steps <= 0 || steps > record.CompleteSteps()) {
    throw Error(record.source, fmt::format("cannot replay {} steps: the log holds {} complete steps", steps,
                                           record.CompleteSteps()));
  }
  lockstep::RunIdentity id = IdentityOf(s, run_id);
  id.n_steps = steps;
  const lockstep::LockstepConfig config = LockstepOf(s);
  // The roles not live answer from the record: their "recorded" rows (answer step k once desired_t k
  // requests it; the recorded clock runs the integrator's ordinary row). A live clock that answers
  // desired_t k from a message of step k itself ("same_sample": measured_t k) cannot have that
  // message's recorded owner wait for desired_t k (a cycle): the owner keeps its ordinary row, whose
  // inputs come before (the plant: command_t k-1), and answers from the record as the live one would.
  lockstep::Wiring wiring = WiringOf(s);
  const lockstep::ResolvedRole& clock = wiring.Clock();
  const bool live_clock = IsLive(live, clock.role());
  auto clock_needs_at_k = [&](const lockstep::ResolvedRole& r) {
    for (int i = 0; live_clock && i < clock.row->n_inputs(); ++i) {
      if (clock.row->inputs[i].channel == r.row->answer && clock.row->inputs[i].offset == 0) return true;
    }
    return false;
  };
  std::vector<lockstep::RoleVariant> variants;
  for (const lockstep::ResolvedRole& r : wiring.roles()) {
    const bool live_role = IsLive(live, r.role());
    if (!live_role && !r.row->clock && !clock_needs_at_k(r)) {
      variants.push_back({r.role(), lockstep::kRecordedVariant});
    } else if (!r.row->variant.empty() && (live_role || !r.row->clock)) {
      variants.push_back({r.role(), r.row->variant});
    }
  }
  wiring = lockstep::Wiring::Resolve(variants);
  std::unique_ptr<lockstep::Channels> bus;
  if (external.empty()) {
    bus = std::make_unique<lockstep::InprocChannels>();
  } else {
    auto bridge = std::make_unique<lockstep::BridgedChannels>(udpm_url, external, wiring);
    if (!bridge->good()) throw Error("", bridge->error());
    bus = std::move(bridge);
  }
  std::vector<std::unique_ptr<lockstep::Participant>> owned;
  for (std::string_view role : lockstep::kBuildOrder) {
    if (std::find(external.begin(), external.end(), role) != external.end()) continue;  // the user's
    if (IsLive(live, role)) {
      owned.push_back(MakeParticipant(role, s, id, nullptr, out_dir, {}, wiring));
    } else if (role == "integrator") {
      owned.push_back(std::make_unique<RecordedClock>(&record.desired, id, config, wiring));
    } else if (role == "controller") {
      owned.push_back(std::make_unique<RecordedAnswer<rths::command_t>>(role, &record.command, id, config, wiring));
    } else if (role == "plant") {
      owned.push_back(std::make_unique<RecordedAnswer<rths::measured_t>>(role, &record.measured, id, config, wiring));
    } else {
      owned.push_back(std::make_unique<RecordedAnswer<rths::current_t>>(role, &record.current, id, config, wiring));
    }
  }
  std::vector<lockstep::Participant*> group;
  for (auto& p : owned) group.push_back(p.get());
  for (auto* p : group) p->Attach(bus.get());
  lockstep::RunLoop(bus.get(), group, stop);
  std::vector<Outcome> outcomes;
  for (const auto* p : group) outcomes.push_back(OutcomeOf(*p));
  return outcomes;
}

}  // namespace rths::participants
