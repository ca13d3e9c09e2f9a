// rths run --external, the mixed transport and the liveness of external participants
// (docs/participant.md, "Liveness" and "Failure rules"): the built-in participants in one process
// bridged to the user's plant on udpm give the payloads of an all-udpm and of a memq run; a plant
// killed on this host is noticed through its pid (not the stall budget) and named with its signal;
// its ABORT names it and its reason; one on "another host" (no pid: a ttl=1 URL) is lost after
// five missed heartbeats, or, declaring neither, by the stall budget with a message saying so.
#include <doctest/doctest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "external_support.h"
#include "io/run_log.h"
#include "core/exit_code.h"
#include "run_support.h"
#include "udpm_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace rths_test;

namespace {

/// A run long enough (20 s simulated) that the plant is killed while it runs.
const char* kLong = "[run]\nname = \"liveness\"\nduration_s = 20\n";

/// Starts the built-in plant in the background as the user's participant (behind `prefix`, e.g.
/// "ip netns exec B", which execs it); its pid.
pid_t StartPlant(const fs::path& dir, const PrintedRun& run, const std::string& url, const std::string& extra = "",
                 const std::string& prefix = "") {
  const std::string cmd = "(" + prefix + " " + BuiltInPlant(url, run.run_id, run.scenario, dir, extra) + " > " +
                          (dir / "plant.out").string() + " 2>&1 & echo $! > " + (dir / "plant.pid").string() + ")";
  REQUIRE(std::system(cmd.c_str()) == 0);
  return static_cast<pid_t>(std::stol(Slurp(dir / "plant.pid")));
}

/// Kills the plant with SIGKILL once the run has logged some steps; how long the run took to exit
/// after the kill [s] (the run's summary in dir/out).
double KillPlantAndWait(const fs::path& dir, const PrintedRun& run, pid_t plant) {
  for (int i = 0; i < 200 && (!fs::exists(dir / "out" / "log.lcm") || fs::file_size(dir / "out" / "log.lcm") < 100000);
       ++i) {
    ::usleep(20000);
  }
  REQUIRE(::kill(plant, SIGKILL) == 0);
  const auto killed = std::chrono::steady_clock::now();
  while (!Exited(run.pid)) ::usleep(5000);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
}

std::string RunArgs(const fs::path& dir, const fs::path& scenario, const std::string& more = "") {
  return "--join-timeout-s 30 " + more + " --out " + (dir / "out").string() + " " + scenario.string();
}

}  // namespace

TEST_CASE("mixed (the default with --external), all-udpm and memq runs give the same payloads") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("mixed_same");
  const fs::path scenario = WriteScenario(dir, "[run]\nname = \"mixed\"\nduration_s = 0.5\n");
  const std::string reference = ReferenceDigest(dir, scenario);
  for (const std::string transport : {"", "--transport udpm"}) {
    CAPTURE(transport);
    const fs::path sub = dir / (transport.empty() ? "mixed" : "udpm");
    fs::create_directories(sub);
    REQUIRE(RunWithExternalPlant(sub, RunArgs(sub, scenario, transport), "", "") == 0);
    const auto j = nlohmann::json::parse(Slurp(sub / "out" / "summary.json"));
    CHECK(j["transport"] == (transport.empty() ? "mixed" : "udpm"));
    const auto& plant = j["participants"]["plant"];
    CHECK(plant["external"] == true);
    CHECK(plant["observed"] == "finished");
    CHECK(plant["exit_code"] == 0);
    CHECK(plant.contains("link"));  // as the clock saw it
    CHECK(j["participants"]["integrator"]["peers"]["plant"]["answers"].get<int>() == 1000);
    CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((sub / "out" / "log.lcm").string())) == reference);
  }
}

TEST_CASE("kill -9 of an external plant on this host: noticed through its pid, named, exit 128+9") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  for (const std::string transport : {"", "--transport udpm"}) {
    CAPTURE(transport);
    const auto dir = TempDir(transport.empty() ? "kill_mixed" : "kill_udpm");
    const fs::path scenario = WriteScenario(dir, kLong);
    // A stall budget of 10 minutes: only the pid watch can stop this run before the test's timeout.
    const PrintedRun run = StartExternalRun(dir, RunArgs(dir, scenario, transport + " --set lockstep.stall_budget_s=600"));
    const pid_t plant = StartPlant(dir, run, run.url);
    const double took_s = KillPlantAndWait(dir, run, plant);
    MESSAGE("the run exited " << took_s << " s after kill -9 of the plant ("
                              << std::string(transport.empty() ? "mixed" : "udpm") << ")");
    const auto j = WaitExternalRun(run, dir / "out");
    CHECK(j["exit_code"] == 128 + SIGKILL);
    CHECK(j["stopped"].get<std::string>().find("plant was killed by signal 9") != std::string::npos);
    const auto& p = j["participants"]["plant"];
    CHECK(p["observed"] == "killed");
    CHECK(p["signal"] == SIGKILL);
    CHECK(j["participants"]["integrator"]["peers"]["plant"]["loss"]["died"] == true);
    CHECK(j["participants"]["integrator"]["peers"]["plant"]["pid"] == plant);
    // The log is valid up to the last completed step.
    const auto log = rths::io::ReadRunLog((dir / "out" / "log.lcm").string());
    CHECK(log.CompleteSteps() > 0);
    CHECK(log.CompleteSteps() < 40000);
  }
}

TEST_CASE("an external plant that sends ABORT with a reason is named with its reason: exit 9") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("ext_abort");
  // The built-in plant, run as the user's, fails in its own step 300 and says why in its ABORT.
  const fs::path scenario = WriteScenario(
      dir, "[run]\nname = \"abort\"\nduration_s = 0.5\n[faults.process]\nrole = \"plant\"\nkind = \"throw\"\nat_step = 300\n");
  CHECK(RunWithExternalPlant(dir, RunArgs(dir, scenario), "", "") == rths::kExitExternalAbort);
  const auto j = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  const std::string stopped = j["stopped"].get<std::string>();
  CHECK(stopped.find("plant (external) aborted the run") != std::string::npos);
  CHECK(stopped.find("injected fault") != std::string::npos);  // its own reason
  CHECK(j["participants"]["plant"]["observed"] == "aborted");
  CHECK(j["participants"]["logger"]["exit_code"] == rths::kExitPeerAbort);  // told to stop, not blamed
  CHECK(rths::io::ReadRunLog((dir / "out" / "log.lcm").string()).CompleteSteps() >= 299);
}

TEST_CASE("a participant from another host (no pid): lost after 5 missed heartbeats, or by the stall budget") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  // ttl=1: the participant cannot know it shares the clock's host, so it gives no pid.
  const std::string url = "udpm://239.255.76.67:" + std::to_string(20000 + ::getpid() % 20000) + "?ttl=1";
  SUBCASE("heartbeat every 0.1 s: lost (exit 10) and the message says how") {
    const auto dir = TempDir("heartbeat");
    const fs::path scenario = WriteScenario(dir, kLong);
    const PrintedRun run =
        StartExternalRun(dir, RunArgs(dir, scenario, "--lcm-url '" + url + "' --set lockstep.stall_budget_s=600"));
    const pid_t plant = StartPlant(dir, run, url, "--heartbeat-s 0.1");
    const double took_s = KillPlantAndWait(dir, run, plant);
    MESSAGE("the run exited " << took_s << " s after kill -9 of a plant beating every 0.1 s");
    const auto j = WaitExternalRun(run, dir / "out");
    CHECK(j["exit_code"] == rths::kExitExternalLost);
    const auto& peer = j["participants"]["integrator"]["peers"]["plant"];
    CHECK(peer["pid"] == 0);
    CHECK(peer["heartbeat_s"] == doctest::Approx(0.1));
    CHECK(peer["loss"]["died"] == false);
    CHECK(j["participants"]["plant"]["observed"] == "lost");
    CHECK(j["stopped"].get<std::string>().find("no HEARTBEAT for") != std::string::npos);
  }
  SUBCASE("the plant in another network namespace over a veth pair, beating every 0.1 s: lost, exit 10") {
    NetnsPair ns;
    if (!ns.ok) FAIL(NetnsPair::Error());
    const auto dir = TempDir("heartbeat_netns");
    const fs::path scenario = WriteScenario(dir, kLong);
    const PrintedRun run = StartExternalRun(
        dir, RunArgs(dir, scenario, "--lcm-url '" + url + "' --set lockstep.stall_budget_s=600"), "ip netns exec " + ns.a);
    const pid_t plant = StartPlant(dir, run, url, "--heartbeat-s 0.1", "ip netns exec " + ns.b);
    const double took_s = KillPlantAndWait(dir, run, plant);
    MESSAGE("the run exited " << took_s << " s after kill -9 of a plant in another namespace beating every 0.1 s");
    const auto j = WaitExternalRun(run, dir / "out");
    CHECK(j["exit_code"] == rths::kExitExternalLost);
    CHECK(j["participants"]["integrator"]["peers"]["plant"]["pid"] == 0);
    CHECK(j["participants"]["plant"]["observed"] == "lost");
  }
  SUBCASE("neither pid nor heartbeat: the stall budget, and the message says why it took that long") {
    const auto dir = TempDir("no_liveness");
    const fs::path scenario = WriteScenario(dir, kLong);
    const PrintedRun run =
        StartExternalRun(dir, RunArgs(dir, scenario, "--lcm-url '" + url + "' --set lockstep.stall_budget_s=1"));
    const pid_t plant = StartPlant(dir, run, url);
    KillPlantAndWait(dir, run, plant);
    const auto j = WaitExternalRun(run, dir / "out");
    CHECK(j["exit_code"] == rths::kExitLockstep);
    const std::string stopped = j["stopped"].get<std::string>();
    CHECK(stopped.find("plant stopped answering") != std::string::npos);
    CHECK(stopped.find("neither its pid nor a heartbeat") != std::string::npos);
    CHECK(j["participants"]["plant"]["observed"] == "silent");
  }
}

TEST_CASE("the README's external example with --set: the printed scenario is the run's own, and it joins") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("external_set");
  const fs::path scenario = WriteScenario(dir, "[run]\nname = \"set\"\nduration_s = 0.5\n");
  const PrintedRun run = StartExternalRun(dir, RunArgs(dir, scenario, "--set run.duration_s=0.25"));
  CHECK(run.scenario == (dir / "out" / "scenario.toml").string());  // not the original file
  const std::string plant = "timeout 60 " + BuiltInPlant(run.url, run.run_id, run.scenario, dir) + " > " +
                            (dir / "plant.out").string() + " 2>&1";
  CHECK(std::system(plant.c_str()) == 0);
  const auto j = WaitExternalRun(run, dir / "out");
  CHECK(j["exit_code"] == 0);
  CHECK(j["steps"] == 500);
  // The original file's hash is refused, as the printed line warns.
  CHECK(Slurp(dir / "run.out").find("give your participant this file") != std::string::npos);
}

TEST_CASE("rths replay --live plant --external plant: the user's plant, replayed, reproduces the recording") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("replay_external");
  const fs::path scenario = WriteScenario(dir, "[run]\nname = \"replay_ext\"\nduration_s = 0.5\n");
  const fs::path recorded = dir / "recorded";
  fs::create_directories(recorded);
  REQUIRE(RunMemq({rths::scenario::LoadScenario(scenario.string())}, recorded).code == 0);
  fs::copy_file(scenario, recorded / "scenario.toml");
  const PrintedRun run = StartExternalRun(
      dir, recorded.string() + " --live plant --external plant --join-timeout-s 30 --out " + (dir / "out").string(),
      "", "rths-replay");
  CHECK(run.scenario == (recorded / "scenario.toml").string());
  const std::string plant = "timeout 60 " + BuiltInPlant(run.url, run.run_id, run.scenario, dir) + " > " +
                            (dir / "plant.out").string() + " 2>&1";
  CHECK(std::system(plant.c_str()) == 0);
  for (int i = 0; i < 600 && !Exited(run.pid); ++i) ::usleep(100000);
  const auto j = nlohmann::json::parse(Slurp(dir / "out" / "replay.json"));
  CAPTURE(Slurp(dir / "run.out"));
  CHECK(j["identical"] == true);
  CHECK(Slurp(dir / "run.out").find("identical: the live outputs reproduce the recording") != std::string::npos);
}
