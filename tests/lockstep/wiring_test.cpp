// The step table (lib/lockstep/step_table.h) resolved into a run's wiring: the barrier, the
// wake-ups and the checks, against the tables of docs/lockstep.md.
#include <doctest/doctest.h>

#include <string>

#include "core/error.h"
#include "lockstep/wiring.h"

using rths::lockstep::Wiring;

TEST_CASE("the roster and its orders come from the step table") {
  using rths::lockstep::kBuildOrder;
  using rths::lockstep::kRoster;
  CHECK(std::string(kRoster[0]) == "integrator");
  CHECK(std::string(kRoster[1]) == "controller");
  CHECK(std::string(kRoster[2]) == "plant");
  CHECK(std::string(kRoster[3]) == "semiactive");
  CHECK(std::string(kRoster[4]) == "logger");
  CHECK(std::string(kBuildOrder[0]) == "logger");
  CHECK(std::string(kBuildOrder[4]) == "integrator");
  CHECK(std::string(rths::lockstep::kClockRole) == "integrator");
}

TEST_CASE("docs/lockstep.md: every step's waits, wake-ups and barrier") {
  // "Wake-ups": six per step; the logger holds measured_t k+1 before it acknowledges step k.
  CHECK(Wiring::Resolve().Describe() ==
        "integrator: desired_t k <- measured_t k-1, command_t k-1, measured_t k, current_t k-1, ack_t k-1; "
        "wakes for ack_t k-1; barrier -\n"
        "controller: command_t k <- desired_t k, measured_t k; wakes for desired_t k; barrier command_t k\n"
        "plant: measured_t k <- command_t k-1, current_t k-1; wakes for command_t k-1, current_t k-1; "
        "barrier measured_t k, measured_t k+1\n"
        "semiactive: current_t k <- desired_t k, measured_t k; wakes for desired_t k; barrier current_t k\n"
        "logger: ack_t k <- desired_t k, command_t k, measured_t k, current_t k, measured_t k+1; "
        "wakes for measured_t k+1; barrier ack_t k\n");
  // The "ideal" plant answers desired_t k: desired -> plant -> controller / semiactive.
  CHECK(Wiring::Resolve({{"plant", "ideal"}}).Describe() ==
        "integrator: desired_t k <- measured_t k-1, command_t k-1, current_t k-1, ack_t k-1; "
        "wakes for ack_t k-1; barrier -\n"
        "controller: command_t k <- desired_t k, measured_t k; wakes for measured_t k; barrier command_t k\n"
        "plant: measured_t k <- desired_t k, current_t k-1; wakes for desired_t k; barrier measured_t k\n"
        "semiactive: current_t k <- desired_t k, measured_t k; wakes for measured_t k; barrier current_t k\n"
        "logger: ack_t k <- desired_t k, command_t k, measured_t k, current_t k; "
        "wakes for command_t k, current_t k; barrier ack_t k\n");
}

TEST_CASE("a stalled step blames in the step's order: plant, controller, semiactive, logger") {
  for (const char* variant : {"", "ideal"}) {
    const Wiring w = Wiring::Resolve({{"plant", variant}});
    std::string order;
    for (int i : w.step_order()) order += std::string(w.roles()[i].role()) + " ";
    CHECK(order == "plant controller semiactive logger ");
  }
}

TEST_CASE("a replay's recorded roles answer the request, and the wiring stays acyclic") {
  const Wiring w = Wiring::Resolve({{"controller", "recorded"}, {"plant", "recorded"}, {"semiactive", "recorded"}});
  CHECK(w.Of("plant").n_waits == 1);
  CHECK(w.Of("logger").n_waits == 4);  // no measured_t k+1: the recorded plant answers desired_t k
}

TEST_CASE("the wiring is checked before a run") {
  CHECK_THROWS_AS(Wiring::Resolve({{"plant", "no such variant"}}), rths::Error);
  CHECK_THROWS_AS(Wiring::Resolve({{"nobody", ""}}), rths::Error);
  CHECK_THROWS_AS(Wiring::Resolve().Of("nobody"), rths::Error);
}

TEST_CASE("the \"same_sample\" integrator (maRTHS) answers desired_t k from measured_t k; with the ideal plant it "
          "is a cycle") {
  // Its input, measured_t k, is already in the barrier of step k-1 (the plant's measured_t k+1):
  // the waits are those of the ordinary row, the row's input is step k's.
  const Wiring w = Wiring::Resolve({{"integrator", "same_sample"}});
  CHECK(std::string(w.Clock().row->variant) == "same_sample");
  CHECK(w.Clock().row->inputs[0].channel == rths::lockstep::kMeasured);
  CHECK(w.Clock().row->inputs[0].offset == 0);
  std::string ordinary = Wiring::Resolve().Describe();
  ordinary.replace(0, ordinary.find('\n'),
                   "integrator: desired_t k <- measured_t k, command_t k-1, measured_t k-1, current_t k-1, ack_t k-1; "
                   "wakes for ack_t k-1; barrier -");
  CHECK(w.Describe() == ordinary);
  // desired_t k <- measured_t k <- desired_t k (the ideal plant answers desired_t k).
  CHECK_THROWS_AS(Wiring::Resolve({{"integrator", "same_sample"}, {"plant", "ideal"}}), rths::Error);
}
