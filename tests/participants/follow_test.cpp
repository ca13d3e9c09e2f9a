// Follow mode's hold policy (docs/replay.md, "lcm-logplayer into a live participant"), in one
// process on the in-process queue: a recorded run is fed step by step into a plant in follow mode
// with chosen messages left out, as lcm-logplayer's would be lost. Checked: which steps it answers
// exactly, from a held input, after a hold, or never; that exact answers are the recorded ones;
// and that every answer is the one a plant fed the held inputs outright would give (zero-order hold).
#include <doctest/doctest.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "alloc_counter.h"
#include "io/run_log.h"
#include "lockstep/follow_ledger.h"
#include "lockstep/protocol.h"
#include "lockstep/transport.h"
#include "participants/factory.h"
#include "participants/group.h"
#include "run_support.h"
#include "test_support.h"

namespace {

using rths::lockstep::Channel;
using rths::lockstep::FollowStep;
using rths_test::TempDir;

/// What a plant in follow mode answered, and its ledger as the outcome file has it.
struct Fed {
  std::vector<std::optional<rths::lockstep::Bytes>> answers;  ///< measured_t k as published
  nlohmann::json follow;
  int exit_code = -1;
  std::int64_t n_answers = 0;  ///< answers published
  long allocations = -1;       ///< heap allocations from step `count_from` to the feed's end (keep = false)
};

/// (channel, k) of a feed message.
using Key = std::pair<Channel, std::int64_t>;

/// Feeds `log`'s desired_t, command_t and current_t in step order into a plant in follow mode
/// (plant.kind of `s`). A message for which `lost` is true is left out, or, with `substitute`, replaced
/// by the last message of its channel that was not lost, re-stamped with its k (the held input
/// given outright). Steps after `last_fed` are not fed at all. `keep`: keep the answers' bytes
/// (else only count them, and count the heap allocations from step `count_from` on).
Fed Feed(const rths::scenario::Scenario& s, const rths::io::RunLog& log, const std::function<bool(Key)>& lost,
         bool substitute, std::int64_t last_fed, bool keep = true, std::int64_t count_from = 100) {
  rths::lockstep::InprocChannels channels;
  const auto id = rths::participants::IdentityOf(s, log.run_id);
  auto plant = rths::participants::MakeParticipant("plant", s, id, nullptr, TempDir("follow_feed").string());
  plant->Attach(&channels);
  Fed fed;
  fed.answers.resize(static_cast<std::size_t>(id.n_steps));
  struct Sink {
    Fed* fed;
    bool keep;
    rths::measured_t m;
  } sink{&fed, keep, {}};
  channels.Subscribe(
      rths::lockstep::kChMeasured,
      [](void* ctx, const lcm::ReceiveBuffer* rbuf) {
        auto* s = static_cast<Sink*>(ctx);
        ++s->fed->n_answers;
        if (!s->keep) return;
        REQUIRE(s->m.decode(rbuf->data, 0, rbuf->data_size) >= 0);
        const auto* d = static_cast<const std::uint8_t*>(rbuf->data);
        s->fed->answers.at(static_cast<std::size_t>(s->m.k)) = rths::lockstep::Bytes(d, d + rbuf->data_size);
      },
      &sink);
  plant->Follow({});
  rths::desired_t last_desired = log.desired.at(0);
  rths::command_t last_command = log.command.at(0);
  rths::current_t last_current = log.current.at(0);
  rths::lockstep::Bytes bytes;
  auto send = [&](Channel c, std::int64_t k, const auto& msg, auto* last) {
    if (lost({c, k})) {
      if (!substitute) return;
      const std::int64_t last_k = last->k;
      last->k = k;
      rths::lockstep::Encode(*last, &bytes);
      last->k = last_k;
    } else {
      *last = msg;
      rths::lockstep::Encode(msg, &bytes);
    }
    channels.Publish(rths::lockstep::ChannelName(c), bytes.data(), static_cast<unsigned>(bytes.size()));
    while (channels.queued() > 0) channels.HandleTimeout(0);
  };
  long allocations_from = 0;
  for (std::int64_t k = 0; k <= last_fed && k < id.n_steps; ++k) {
    if (k == count_from) allocations_from = rths_test::AllocationCount();
    const auto i = static_cast<std::size_t>(k);
    send(rths::lockstep::kDesired, k, log.desired.at(i), &last_desired);
    send(rths::lockstep::kCommand, k, log.command.at(i), &last_command);
    send(rths::lockstep::kCurrent, k, log.current.at(i), &last_current);
  }
  if (!keep) fed.allocations = rths_test::AllocationCount() - allocations_from;
  // The feed has ended: the plant is idle past --follow-idle-s.
  plant->Tick(rths::lockstep::SteadyClock::now() + std::chrono::hours(1), true);
  REQUIRE(plant->finished());
  fed.exit_code = plant->exit_code();
  REQUIRE(plant->follow_ledger() != nullptr);
  fed.follow = rths::participants::FollowToJson(*plant->follow_ledger());
  return fed;
}

/// A recorded run of `duration_s` (memq) with `plant_kind`'s plant and the damper switching.
rths::io::RunLog Record(const std::string& name, const std::string& plant_kind, rths::scenario::Scenario* s) {
  const auto dir = TempDir("follow_" + name);
  *s = rths::scenario::LoadScenario(rths_test::WriteScenario(dir, R"(
[run]
duration_s = 0.5
[plant]
kind = ")" + plant_kind + R"("
[semiactive]
mode = "clipped_optimal"
)").string());
  REQUIRE(rths_test::RunMemq({*s}, dir).code == 0);
  auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  REQUIRE(log.CompleteSteps() == s->steps());
  return log;
}

rths::lockstep::Bytes Recorded(const rths::io::RunLog& log, std::int64_t k) {
  rths::lockstep::Bytes b;
  rths::lockstep::Encode(log.measured.at(static_cast<std::size_t>(k)), &b);
  return b;
}

nlohmann::json Ranges(std::initializer_list<std::pair<int, int>> r) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [a, b] : r) j.push_back({a, b});
  return j;
}

}  // namespace

TEST_CASE("follow mode, nothing lost: every step exact, the recorded answers") {
  rths::scenario::Scenario s;
  const auto log = Record("none_lost", "linear", &s);
  const Fed fed = Feed(s, log, [](Key) { return false; }, false, s.steps());
  CHECK(fed.exit_code == 0);
  CHECK(fed.follow["exact"] == s.steps());
  CHECK(fed.follow["held"] == 0);
  CHECK(fed.follow["resumed"] == 0);
  CHECK(fed.follow["unseen"] == 0);
  for (std::int64_t k = 0; k < s.steps(); ++k) {
    REQUIRE(fed.answers[static_cast<std::size_t>(k)].has_value());
    CHECK(*fed.answers[static_cast<std::size_t>(k)] == Recorded(log, k));
  }
}

TEST_CASE("follow mode, inputs lost: held at the one before, counted, and resumed at the next complete step") {
  for (const std::string kind : {"linear", "ideal"}) {
    CAPTURE(kind);
    rths::scenario::Scenario s;
    const auto log = Record("lost_" + kind, kind, &s);
    REQUIRE(s.steps() == 1000);
    // A lost command_t 300 and current_t 301 (inputs of plant steps 301 and 302), a lost desired_t
    // 500 (the request of step 500), steps 700-719 lost whole, and nothing fed after step 950.
    const std::set<Key> lost_set = {{rths::lockstep::kCommand, 300}, {rths::lockstep::kCurrent, 301},
                                    {rths::lockstep::kDesired, 500}};
    auto lost = [&](Key key) { return lost_set.count(key) > 0 || (key.second >= 700 && key.second <= 719); };
    const Fed fed = Feed(s, log, lost, false, 950);
    CHECK(fed.exit_code == 0);  // finished; `rths-plant` turns an inexact ledger into exit 11
    CHECK(fed.follow["n_steps"] == 1000);
    // The ideal plant reads desired_t k itself (y_k = r_k): its lost request is a held input too.
    const bool ideal = kind == "ideal";
    if (ideal) {
      // Ideal: measured k from desired k and current k-1. Lost: current 301 -> step 302; desired
      // 500 -> 500; 700-719 whole -> 700-720 (current 719 -> 720). command_t is not an input.
      CHECK(fed.follow["held_steps"] == Ranges({{302, 302}, {500, 500}, {700, 720}}));
      CHECK(fed.follow["exact"] == 302);
    } else {
      CHECK(fed.follow["held_steps"] == Ranges({{301, 302}, {701, 720}}));
      CHECK(fed.follow["exact"] == 301);
    }
    // Step 950 is the last fed. The linear plant answers measured_t 951 from command_t and current_t
    // 950 without waiting for the request; the ideal one needs desired_t 951. The rest: never seen.
    const int last = ideal ? 950 : 951;
    CHECK(fed.follow["unseen_steps"] == Ranges({{last + 1, 999}}));
    CHECK(fed.follow["unseen"] == 999 - last);
    const std::int64_t held = fed.follow["held"];
    CHECK(fed.follow["resumed"] == 1000 - (999 - last) - held - fed.follow["exact"].get<std::int64_t>());
    // Exact answers are the recorded ones.
    for (std::int64_t k = 0; k < fed.follow["exact"].get<std::int64_t>(); ++k) {
      REQUIRE(fed.answers[static_cast<std::size_t>(k)].has_value());
      CHECK(*fed.answers[static_cast<std::size_t>(k)] == Recorded(log, k));
    }
    // A held step does not give the recorded answer (the damper's current switches).
    int differ = 0;
    for (std::int64_t k = 701; k <= 720; ++k) differ += *fed.answers[static_cast<std::size_t>(k)] != Recorded(log, k);
    CHECK(differ > 0);
    // Every answer is the one a plant given the held inputs outright gives (all exact for it).
    const Fed outright = Feed(s, log, lost, true, 950);
    CHECK(outright.follow["exact"] == last + 1);
    for (std::int64_t k = 0; k <= last; ++k) {
      REQUIRE(fed.answers[static_cast<std::size_t>(k)].has_value());
      CHECK(*fed.answers[static_cast<std::size_t>(k)] == *outright.answers[static_cast<std::size_t>(k)]);
    }
    for (std::int64_t k = last + 1; k < 1000; ++k) CHECK_FALSE(fed.answers[static_cast<std::size_t>(k)].has_value());
  }
}

TEST_CASE("follow mode allocates nothing per step once warm, held steps included") {
  rths::scenario::Scenario s;
  const auto log = Record("alloc", "linear", &s);
  // The same losses twice: the first warms the test's in-process queue (it grows to hold the
  // answers a burst releases at once); the second is counted.
  auto lost = [](Key key) {
    const std::int64_t j = key.second % 500;
    return j == 100 || (j >= 200 && j <= 219);
  };
  const Fed fed = Feed(s, log, lost, false, s.steps(), false, 550);
  CHECK(fed.follow["held"].get<int>() == 2 * 21);  // steps 101 and 201-220 of each half
  CHECK(fed.n_answers == s.steps());
  CHECK(fed.allocations == 0);
}

TEST_CASE("follow mode started late: the steps before the feed are held from rest, then it resumes") {
  rths::scenario::Scenario s;
  const auto log = Record("late", "linear", &s);
  const Fed fed = Feed(s, log, [](Key key) { return key.second < 100; }, false, s.steps());
  // Step 0 has no input (at rest) and its answer is the recorded one; 1-100 have none of theirs.
  CHECK(fed.follow["exact"] == 1);
  CHECK(fed.follow["held_steps"] == Ranges({{1, 100}}));
  CHECK(fed.follow["resumed"] == s.steps() - 101);
  CHECK(fed.follow["unseen"] == 0);
}

TEST_CASE("follow mode, nothing of the run heard: no message counted, every step but the first unseen") {
  rths::scenario::Scenario s;
  const auto log = Record("silent", "linear", &s);
  const Fed fed = Feed(s, log, [](Key) { return true; }, false, s.steps());
  CHECK(fed.follow["messages"] == 0);
  // Step 0 needs no input (at rest): the plant answers it at once, as recorded.
  CHECK(fed.follow["exact"] == 1);
  CHECK(fed.follow["unseen_steps"] == Ranges({{1, static_cast<int>(s.steps()) - 1}}));
  const Fed all = Feed(s, log, [](Key) { return false; }, false, s.steps());
  CHECK(all.follow["messages"] == 2 * s.steps());  // command_t and current_t: what the plant reads
}

TEST_CASE("FollowLedger: counts and ranges") {
  rths::lockstep::FollowLedger ledger;
  ledger.Size(10);
  for (int k = 0; k < 3; ++k) ledger.Mark(k, false);
  ledger.Mark(3, true);
  ledger.Mark(4, true);
  for (int k = 5; k < 8; ++k) ledger.Mark(k, false);
  const auto c = ledger.Counts();
  CHECK(c.exact == 3);
  CHECK(c.held == 2);
  CHECK(c.resumed == 3);
  CHECK(c.unseen == 2);
  CHECK(c.total() == 10);
  CHECK_FALSE(c.all_exact());
  CHECK(ledger.at(5) == FollowStep::kResumed);
  CHECK(ledger.Ranges(FollowStep::kHeld) == std::vector<rths::lockstep::StepRange>{{3, 4}});
  CHECK(ledger.Ranges(FollowStep::kUnseen) == std::vector<rths::lockstep::StepRange>{{8, 9}});
}
