// The supervisor as a library (supervisor/run.h): a run made by supervisor::Run in this process
// writes the summary `rths run` writes (the same fields and values, run id, paths and times
// aside) and the same log, on memq and on udpm; a participant that dies takes the run down with
// its log valid to the last step.
#include <doctest/doctest.h>

#include <signal.h>

#include <string>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "supervisor/run.h"
#include "udpm_support.h"
#include "test_support.h"

using namespace rths_test;
namespace sup = rths::supervisor;

namespace {

const char* kShort = R"(
[run]
name = "supervisor"
duration_s = 0.25
)";

nlohmann::json Summary(const fs::path& run) { return nlohmann::json::parse(std::ifstream(run / "summary.json")); }

/// `j` without what differs from one run of the same scenario to the next: the run id, wall and
/// stepping times, the clock's step latencies, the teardown time, the link counters (a loaded host
/// re-requests, on memq too) and, on udpm, the URL (its port).
nlohmann::json Comparable(nlohmann::json j, bool udpm) {
  std::vector<std::string> drop = {"run_id", "wall_s", "stepping_s", "steps_per_s", "teardown_s", "realtime", "link",
                                   "peers"};
  if (udpm) drop.push_back("lcm_url");
  if (j.is_object()) {
    for (const auto& key : drop) j.erase(key);
    for (auto& [key, value] : j.items()) value = Comparable(value, udpm);
  }
  return j;
}

sup::RunRequest Request(const fs::path& scenario, const fs::path& out, const std::string& transport) {
  sup::RunRequest r;
  r.scenario_path = scenario.string();
  r.scenario = rths::scenario::LoadScenario(r.scenario_path);
  r.transport = transport;
  r.out = out;
  r.bin_dir = RTHS_BIN_DIR;
  r.check_disk_space = false;
  return r;
}

std::string Digest(const fs::path& run) {
  return rths::io::PayloadDigest(rths::io::ReadRunLog((run / "log.lcm").string()));
}

/// Runs `transport` through the library and through `rths run`, and compares their folders.
void CompareWithCommand(const std::string& transport) {
  const auto dir = TempDir("compare_" + transport);
  const auto scenario = WriteScenario(dir, kShort);
  const sup::RunResult result = sup::Run(Request(scenario, dir / "lib", transport));
  CHECK(result.summary_written);
  CHECK(result.summary.exit_code == 0);
  CHECK(result.summary.steps == 500);
  std::string output;
  REQUIRE(RunCli(scenario.string() + " --transport " + transport + " --skip-space-check --out " +
                     (dir / "cli").string(),
                 &output) == 0);
  const bool udpm = transport == "udpm";
  CHECK(Comparable(Summary(dir / "lib"), udpm) == Comparable(Summary(dir / "cli"), udpm));
  CHECK(Comparable(result.summary.ToJson(), udpm) == Comparable(Summary(dir / "cli"), udpm));
  CHECK(Digest(dir / "lib") == Digest(dir / "cli"));
  CHECK(Slurp(dir / "lib" / "scenario.toml") == Slurp(dir / "cli" / "scenario.toml"));
}

}  // namespace

TEST_CASE("Run in this process (memq): the summary and log of `rths run --transport memq`") { CompareWithCommand("memq"); }

TEST_CASE("Run as a process group (udpm, a free port): the summary and log of `rths run`") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  CompareWithCommand("udpm");
}

TEST_CASE("Run: a participant that dies takes the run down, named, with the log valid to the last step") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("kill");
  // A stall budget of an hour: only the supervisor's SIGCHLD can end this run quickly.
  const auto scenario = WriteScenario(dir, R"(
[run]
duration_s = 1.0
[lockstep]
stall_budget_s = 3600.0
[faults.process]
kind = "kill"
at_step = 300
role = "plant"
)");
  const sup::RunResult result = sup::Run(Request(scenario, dir / "run", "udpm"));
  const auto& sum = result.summary;
  CHECK(sum.exit_code == 128 + SIGKILL);
  CHECK(sum.status == "failed");
  REQUIRE(sum.failure);
  CHECK(sum.failure->participant == "plant");
  CHECK(sum.failure->what.find("plant was killed by signal 9") != std::string::npos);
  CHECK(sum.failure->teardown_s.has_value());
  CHECK(sum.steps == 300);
  const auto log = rths::io::ReadRunLog((dir / "run" / "log.lcm").string());
  CHECK(log.CompleteSteps() == 300);
  CHECK_FALSE(log.truncated_tail);
  CHECK(Summary(dir / "run")["failure"]["participant"] == "plant");
}

TEST_CASE("Run refuses before a byte is written: a memq run with a process fault, a folder in use") {
  const auto dir = TempDir("refuse");
  const auto scenario = WriteScenario(dir, "[faults.process]\nkind = \"kill\"\nat_step = 3\nrole = \"plant\"\n");
  try {
    sup::Run(Request(scenario, dir / "memq", "memq"));
    FAIL("no RunError");
  } catch (const sup::RunError& e) {
    CHECK(e.exit_code() == rths::kExitUsage);
    CHECK(std::string(e.what()).find("use --transport udpm") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(dir / "memq"));
  fs::create_directories(dir / "used");
  std::ofstream(dir / "used" / "x") << "x";
  const auto ok = WriteScenario(dir / "used", kShort);
  try {
    sup::Run(Request(ok, dir / "used", "memq"));
    FAIL("no RunError");
  } catch (const sup::RunError& e) {
    CHECK(e.exit_code() == rths::kExitUsage);
    CHECK(std::string(e.what()).find("refusing to overwrite") != std::string::npos);
  }
}
