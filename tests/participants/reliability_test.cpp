// Reliability (docs/lockstep.md "Repair", "When things go wrong"): any single lost,
// duplicated, delayed or reordered message is repaired; random faults on every channel leave the
// run bit-identical; a dead or stopped participant is named; a full disk stops the run with the
// files ending on the last acknowledged step; starved CPUs and tiny socket buffers only slow a
// run down.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "run_support.h"
#include "udpm_support.h"
#include "test_support.h"

using namespace rths_test;
using rths::io::PayloadDigest;
using rths::io::ReadRunLog;
using Action = rths::lockstep::TargetedFault::Action;

namespace {

/// 200 steps, quick re-requests: a repair costs one or two round trips after 10 ms.
const char* kTiny = R"(
[run]
name = "reliability"
duration_s = 0.1
[lockstep]
rerequest_ms = 10.0
stall_budget_s = 5.0
handshake_timeout_s = 10.0
)";

std::string Digest(const fs::path& dir) { return PayloadDigest(ReadRunLog((dir / "log.lcm").string())); }

nlohmann::json Summary(const fs::path& run) { return nlohmann::json::parse(std::ifstream(run / "summary.json")); }

const char* ActionName(Action a) {
  switch (a) {
    case Action::kDrop: return "drop";
    case Action::kDuplicate: return "duplicate";
    case Action::kDelay: return "delay";
    case Action::kReorder: return "reorder";
  }
  return "?";
}

/// Lines of signals.csv (the header included); checks the file ends on a whole row.
std::int64_t CsvLines(const fs::path& csv) {
  std::ifstream in(csv, std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK((all.empty() || all.back() == '\n'));
  return std::count(all.begin(), all.end(), '\n');
}

}  // namespace

TEST_CASE("any single lost, duplicated, delayed or reordered message is repaired (every receiver, channel, step)") {
  const auto base = TempDir("single_clean");
  const auto s = rths::scenario::LoadScenario(WriteScenario(base, kTiny).string());
  REQUIRE(RunMemq({s}, base).code == 0);
  const std::string reference = Digest(base);
  const std::int64_t last = s.steps() - 1;
  // Every (receiver, channel) pair of the step table, and the handshake each receiver hears.
  const std::vector<std::pair<std::string, std::vector<std::string>>> inputs = {
      {"integrator", {"RTHS_MEASURED", "RTHS_COMMAND", "RTHS_CURRENT", "RTHS_ACK"}},
      {"controller", {"RTHS_DESIRED", "RTHS_MEASURED"}},
      {"plant", {"RTHS_COMMAND", "RTHS_CURRENT"}},
      {"semiactive", {"RTHS_DESIRED", "RTHS_MEASURED"}},
      {"logger", {"RTHS_DESIRED", "RTHS_COMMAND", "RTHS_MEASURED", "RTHS_CURRENT"}}};
  int runs = 0, repaired_runs = 0;
  for (const auto& [role, channels] : inputs) {
    for (const auto& channel : channels) {
      for (const std::int64_t k : {std::int64_t{0}, std::int64_t{57}, last}) {
        for (const Action a : {Action::kDrop, Action::kDuplicate, Action::kDelay, Action::kReorder}) {
          CAPTURE(role);
          CAPTURE(channel);
          CAPTURE(k);
          CAPTURE(ActionName(a));
          const auto dir = TempDir("single");
          rths::lockstep::Faults f;
          f.network.delay_ms = 30.0;  // longer than a re-request: the late copy arrives after the repair
          f.targeted.push_back({a, channel, k});
          const auto r = RunMemq({s}, dir, role, f);
          REQUIRE(r.code == 0);
          const auto log = ReadRunLog((dir / "log.lcm").string());
          CHECK(log.CompleteSteps() == s.steps());
          for (const auto& [ch, d] : log.duplicates) CHECK(d == 0);
          CHECK(PayloadDigest(log) == reference);
          ++runs;
          repaired_runs += a == Action::kDrop;
        }
      }
    }
  }
  // The handshake: REQUEST, GO, DONE and CLOSE at a participant; HELLO and BYE at the clock.
  const std::vector<std::pair<std::string, std::vector<rths::lockstep::Phase>>> phases = {
      {"controller", {rths::lockstep::kRequest, rths::lockstep::kGo, rths::lockstep::kDone, rths::lockstep::kClose}},
      {"plant", {rths::lockstep::kRequest, rths::lockstep::kGo, rths::lockstep::kDone, rths::lockstep::kClose}},
      {"logger", {rths::lockstep::kRequest, rths::lockstep::kGo, rths::lockstep::kDone, rths::lockstep::kClose}},
      {"integrator", {rths::lockstep::kHello, rths::lockstep::kBye}}};
  for (const auto& [role, list] : phases) {
    for (const auto phase : list) {
      for (const Action a : {Action::kDrop, Action::kDuplicate, Action::kDelay, Action::kReorder}) {
        CAPTURE(role);
        CAPTURE(static_cast<int>(phase));
        CAPTURE(ActionName(a));
        const auto dir = TempDir("single_hs");
        rths::lockstep::Faults f;
        f.network.delay_ms = 30.0;
        rths::lockstep::TargetedFault t{a, "RTHS_HANDSHAKE"};
        t.phase = phase;
        f.targeted.push_back(t);
        // GO goes out in several copies: lose them all (a participant must start on step 0).
        if (phase == rths::lockstep::kGo && a == Action::kDrop) {
          f.targeted.push_back(t);
          f.targeted.push_back(t);
        }
        const auto r = RunMemq({s}, dir, role, f);
        REQUIRE(r.code == 0);
        CHECK(Digest(dir) == reference);
        ++runs;
      }
    }
  }
  MESSAGE(runs << " single-fault runs, all bit-identical to the clean run");
}

TEST_CASE("the ideal plant (measured_t k from desired_t k): a lost desired_t is repaired too") {
  const std::string text = std::string(kTiny) + "[plant]\nkind = \"ideal\"\n";
  const auto base = TempDir("ideal_clean");
  const auto s = rths::scenario::LoadScenario(WriteScenario(base, text).string());
  REQUIRE(RunMemq({s}, base).code == 0);
  for (const std::int64_t k : {std::int64_t{0}, std::int64_t{99}}) {
    CAPTURE(k);
    const auto dir = TempDir("ideal_drop");
    rths::lockstep::Faults f;
    f.targeted.push_back({Action::kDrop, "RTHS_DESIRED", k});
    REQUIRE(RunMemq({s}, dir, "plant", f).code == 0);
    CHECK(Digest(dir) == Digest(base));
  }
}

TEST_CASE("5 % of every kind of fault on every channel: bit-identical, with the repairs counted") {
  const std::string faults = "[faults]\ndrop = 0.05\nduplicate = 0.05\ndelay = 0.05\nreorder = 0.05\n"
                             "delay_ms = 15.0\nseed = 11\n";
  const auto base = TempDir("random_clean");
  const auto clean = rths::scenario::LoadScenario(WriteScenario(base, kTiny).string());
  REQUIRE(RunMemq({clean}, base).code == 0);
  const std::string reference = Digest(base);

  SUBCASE("memq, three seeds") {
    for (int seed : {11, 12, 13}) {
      CAPTURE(seed);
      const auto dir = TempDir("random_memq");
      const std::string text = std::string(kTiny) + "[faults]\ndrop = 0.05\nduplicate = 0.05\ndelay = 0.05\n"
                               "reorder = 0.05\ndelay_ms = 15.0\nseed = " + std::to_string(seed) + "\n";
      const auto s = rths::scenario::LoadScenario(WriteScenario(dir, text).string());
      const auto outcomes = rths::participants::RunGroupInProcess({s}, 7, dir.string());
      REQUIRE(rths::participants::RootCause(outcomes) == nullptr);
      CHECK(Digest(dir) == reference);
      std::int64_t injected = 0, rerequests = 0, repaired = 0;
      for (const auto& o : outcomes) {
        injected += o.stats.injected.dropped + o.stats.injected.duplicated + o.stats.injected.delayed +
                    o.stats.injected.reordered;
        rerequests += o.stats.rerequests;
        repaired += o.stats.repaired;
      }
      CHECK(injected > 100);  // about 20 % of some 3 000 deliveries
      CHECK(rerequests > 0);
      CHECK(repaired > 0);
    }
  }
  SUBCASE("udpm, through the supervisor: summary.json counts re-requests and repairs per participant") {
    if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
    const auto dir = TempDir("random_udpm");
    const auto scen = WriteScenario(dir, std::string(kTiny) + faults);
    std::string output;
    const int code = RunCli(scen.string() + " --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    REQUIRE(code == 0);
    CHECK(Digest(dir / "run") == reference);
    const auto j = Summary(dir / "run");
    CHECK(j["status"] == "completed");
    CHECK(j["link"]["rerequests"].get<int>() > 0);
    CHECK(j["link"]["repaired"].get<int>() > 0);
    CHECK(j["link"]["injected"]["dropped"].get<int>() > 0);
    CHECK(j["participants"]["integrator"]["link"]["rerequests"].get<int>() == j["link"]["rerequests"].get<int>());
    for (const char* role : {"controller", "plant", "semiactive", "logger"}) {
      CAPTURE(role);
      const auto& l = j["participants"][role]["link"];
      CHECK(l["injected"]["dropped"].get<int>() + l["injected"]["delayed"].get<int>() > 0);
      CHECK(l.contains("repaired"));
      CHECK(l.contains("resent"));
    }
    CHECK(output.find("re-requests") != std::string::npos);
    // The logger reports how often a signals.csv row waited for its writer thread; only it.
    CHECK(j["participants"]["logger"]["output_stalls"].get<int>() >= 0);
    CHECK_FALSE(j["participants"]["plant"].contains("output_stalls"));
  }
}

TEST_CASE("a participant killed by a signal is noticed at once (not after the stall budget), named") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  // A stall budget of an hour: only the supervisor's SIGCHLD can end this run quickly (CTest's
  // timeout on this binary catches a regression).
  for (const char* role : {"plant", "logger", "integrator"}) {
    CAPTURE(role);
    const auto dir = TempDir(std::string("kill_") + role);
    const auto scen = WriteScenario(dir, std::string(R"(
[run]
duration_s = 1.0
[lockstep]
stall_budget_s = 3600.0
[faults.process]
kind = "kill"
at_step = 300
role = ")") + role + "\"\n");
    std::string output;
    const int code = RunCli(scen.string() + " --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    CHECK(code == 128 + SIGKILL);
    CHECK(output.find(std::string("FAILED: ") + role + " was killed by signal 9") != std::string::npos);
    const auto log = ReadRunLog((dir / "run" / "log.lcm").string());
    CHECK(log.CompleteSteps() == 300);
    CHECK_FALSE(log.truncated_tail);
    // signals.csv is buffered (docs/lockstep.md "Logging"): a killed logger cannot write the rows
    // it held, so its CSV ends earlier, on a whole row; anyone else's death lets it write them all.
    if (std::string(role) == "logger") {
      CHECK(CsvLines(dir / "run" / "signals.csv") <= 301);
    } else {
      CHECK(CsvLines(dir / "run" / "signals.csv") == 301);
    }
    const auto j = Summary(dir / "run");
    CHECK(j["status"] == "failed");
    CHECK(j["failure"]["participant"] == role);
    CHECK(j["steps"] == 300);
    // The others stopped on the supervisor's ABORT, by themselves.
    for (const auto& [name, p] : j["participants"].items()) {
      if (name == role) continue;
      CAPTURE(name);
      CHECK(p["exit_code"] == rths::kExitPeerAbort);
      CHECK(p["killed_by_supervisor"] == false);
    }
  }
}

TEST_CASE("a stopped participant: a short stop only slows the run; a long one is named, with the step") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto base = TempDir("stop_clean");
  const std::string text = "[run]\nduration_s = 0.5\n[lockstep]\nrerequest_ms = 20.0\n";
  const auto clean = rths::scenario::LoadScenario(WriteScenario(base, text).string());
  REQUIRE(RunMemq({clean}, base).code == 0);

  SUBCASE("plant stopped for 3 s, budget 10 s: finishes bit-identical") {
    const auto dir = TempDir("stop_short");
    const auto scen = WriteScenario(dir, text + "stall_budget_s = 10.0\n[faults.process]\nrole = \"plant\"\n"
                                                "kind = \"stop\"\nat_step = 200\nstop_s = 3.0\n");
    std::string output;
    const int code = RunCli(scen.string() + " --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    CHECK(code == 0);
    CHECK(Digest(dir / "run") == Digest(base));
    CHECK(Summary(dir / "run")["link"]["rerequests"].get<int>() > 0);
  }
  SUBCASE("plant stopped for good, budget 2 s: named, at its step, killed by the supervisor") {
    const auto dir = TempDir("stop_long");
    const auto scen = WriteScenario(dir, text + "stall_budget_s = 2.0\n[faults.process]\nrole = \"plant\"\n"
                                                "kind = \"stop\"\nat_step = 200\n");
    std::string output;
    const int code = RunCli(scen.string() + " --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    CHECK(code == rths::kExitLockstep);
    // It stops before measured_t 200, its answer to command_t 199: part of the barrier of step 199.
    CHECK(output.find("FAILED: step 199: plant stopped answering: no measured_t 200") != std::string::npos);
    CHECK(output.find("the supervisor killed plant") != std::string::npos);
    CHECK(output.find("stopped (SIGSTOP)") != std::string::npos);
    CHECK(output.find("signal 9") == std::string::npos);  // not "plant was killed by signal 9"
    const auto j = Summary(dir / "run");
    CHECK(j["failure"]["participant"] == "plant");
    CHECK(j["failure"]["step"] == 199);
    CHECK(j["participants"]["plant"]["killed_by_supervisor"] == true);
    CHECK(j["participants"]["plant"]["was_stopped"] == true);
    // Those that only waited are not blamed.
    for (const char* role : {"controller", "semiactive", "logger"}) {
      CHECK(j["participants"][role]["exit_code"] == rths::kExitPeerAbort);
    }
    CHECK(ReadRunLog((dir / "run" / "log.lcm").string()).CompleteSteps() == 200);
  }
  SUBCASE("the clock stopped for good: the others' watchdogs name it") {
    const auto dir = TempDir("stop_clock");
    const auto scen = WriteScenario(dir, text + "stall_budget_s = 1.0\n[faults.process]\nrole = \"integrator\"\n"
                                                "kind = \"stop\"\nat_step = 100\n");
    std::string output;
    const int code = RunCli(scen.string() + " --out " + (dir / "run").string(), &output);
    CAPTURE(output);
    CHECK(code == rths::kExitLockstep);
    CHECK(output.find("the clock (integrator) stopped answering") != std::string::npos);
    CHECK(output.find("the supervisor killed integrator") != std::string::npos);
    const auto j = Summary(dir / "run");
    CHECK(j["failure"]["participant"] == "integrator");
    CHECK(j["failure"]["step"] == 99);  // the last step it requested
  }
}

namespace {

/// A 2 MB tmpfs at `dir` if this host lets us mount one (root), for a real "disk full".
bool MountSmallTmpfs(const fs::path& dir) {
  fs::create_directories(dir);
  return std::system(("mount -t tmpfs -o size=2m tmpfs " + dir.string() + " 2>/dev/null").c_str()) == 0;
}
void Unmount(const fs::path& dir) { std::system(("umount " + dir.string() + " 2>/dev/null").c_str()); }

/// Checks a run stopped by a write error: exit 7, named file and error, summary, files cut back.
void CheckWriteFailure(const fs::path& run, int code, const std::string& output, const std::string& error) {
  CAPTURE(output);
  CHECK(code == rths::kExitOutput);
  CHECK(output.find("FAILED: logger exited with code 7: logger: writing " + (run / "log.lcm").string() +
                    " failed: " + error) != std::string::npos);
  const auto log = ReadRunLog((run / "log.lcm").string());
  const std::int64_t steps = log.CompleteSteps();
  CHECK(steps > 100);
  CHECK(steps < 40000);
  // The log holds whole events only, step after step, and the CSV the same steps.
  CHECK_FALSE(log.truncated_tail);
  CHECK_FALSE(log.done);  // the run did not finish, and the log says so
  CHECK(log.count.at("RTHS_DESIRED") == steps);
  CHECK(log.count.at("RTHS_MEASURED") == steps);
  CHECK(CsvLines(run / "signals.csv") == steps + 1);
  CHECK(output.find("the log and signals.csv end on step " + std::to_string(steps - 1)) != std::string::npos);
  const auto j = Summary(run);
  CHECK(j["status"] == "failed");
  CHECK(j["exit_code"] == rths::kExitOutput);
  CHECK(j["failure"]["participant"] == "logger");
  CHECK(j["failure"]["what"].get<std::string>().find(error) != std::string::npos);
  CHECK(j["steps"] == steps);
}

}  // namespace

TEST_CASE("disk full (EFBIG): the run stops with exit 7 naming the file; log and CSV end on the last acknowledged step") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("disk_full");
  const auto scen = WriteScenario(dir, "[run]\nduration_s = 20.0\n");  // about 28 MB of output
  SUBCASE("a file size limit (EFBIG), on any host") {
    std::string output;
    const auto run = dir / "run_fsize";
    // 2 MB, in the shell's 1024-byte blocks.
    const int code = RunCli(scen.string() + " --out " + run.string(), &output, "ulimit -f 2048; ");
    CheckWriteFailure(run, code, output, "File too large");
  }
}

TEST_CASE("disk full on a 2 MB tmpfs (ENOSPC): refused up front; filled during the run, exit 7 "
          "(root only: mount)" * doctest::skip(!IsRoot())) {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("disk_full_tmpfs");
  const auto scen = WriteScenario(dir, "[run]\nduration_s = 20.0\n");  // about 28 MB of output
  const auto mnt = dir / "mnt";
  REQUIRE_MESSAGE(MountSmallTmpfs(mnt), "mount -t tmpfs failed as root");
  std::string output;
  // Checked up front, the run is refused and nothing is created ...
  int code = RunCli(scen.string() + " --out " + (mnt / "run").string(), &output);
  CHECK(code == rths::kExitUsage);
  CHECK(output.find("not enough free disk space: this run writes about 28") != std::string::npos);
  CHECK_FALSE(fs::exists(mnt / "run"));
  // ... and when the disk fills up during the run anyway, the run stops cleanly.
  code = RunCli(scen.string() + " --skip-space-check --out " + (mnt / "run").string(), &output);
  CheckWriteFailure(mnt / "run", code, output, "No space left on device");
  Unmount(mnt);
}

TEST_CASE("interrupt: a run that will write gigabytes is announced; Ctrl-C stops it with its log valid") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("interrupt");
  const auto scen = WriteScenario(dir, "[run]\nduration_s = 3000.0\n");  // 6 M steps, about 4 GB
  const auto run = dir / "run";
  const auto out_txt = dir / "output.txt";
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::setpgid(0, 0);  // a process group of its own, as a shell job: Ctrl-C reaches all of it
    const std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-run " + scen.string() + " --out " + run.string() +
                            " > " + out_txt.string() + " 2>&1";
    ::execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait until a few hundred steps are on disk (or the supervisor has exited: no space).
  int status = 0;
  bool exited = false;
  for (int i = 0; i < 3000 && !exited; ++i) {
    if (fs::exists(run / "signals.csv") && fs::file_size(run / "signals.csv") > 100000) break;
    ::usleep(10000);
    exited = ::waitpid(pid, &status, WNOHANG) == pid;
  }
  if (!exited) {
    ::kill(-pid, SIGINT);  // Ctrl-C: to the supervisor and every participant
    REQUIRE(::waitpid(pid, &status, 0) == pid);
  }
  std::ifstream in(out_txt);
  const std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CAPTURE(output);
  if (exited) {  // this host lacks the space: refused up front, nothing made
    CHECK(WEXITSTATUS(status) == rths::kExitUsage);
    CHECK(output.find("not enough free disk space") != std::string::npos);
    CHECK_FALSE(fs::exists(run));
    return;
  }
  CHECK(output.find("warning: this run will write about 4") != std::string::npos);
  CHECK(WEXITSTATUS(status) == 130);
  const auto log = ReadRunLog((run / "log.lcm").string());
  CHECK(log.CompleteSteps() > 100);
  CHECK(CsvLines(run / "signals.csv") == log.CompleteSteps() + 1);
  const auto j = Summary(run);
  CHECK(j["status"] == "interrupted");
  CHECK(j["steps"] == log.CompleteSteps());
  // Each stopped cleanly (exit 4, output flushed). Ctrl-C reaches every process of the group at
  // once, and the supervisor also broadcasts ABORT on it: a participant may handle either first
  // (seen once in CI on a loaded host), so either reason is a clean stop.
  for (const auto& [name, p] : j["participants"].items()) {
    CAPTURE(name);
    CHECK(p["exit_code"] == rths::kExitPeerAbort);
    const std::string why = p["message"].get<std::string>();
    CHECK((why == "stopped by a signal (SIGINT or SIGTERM)" ||
           why == "supervisor aborted the run: interrupted by the user"));
  }
}

TEST_CASE("no multicast route: one clear message, nothing left behind, memq works with the same --out "
          "(root only: a network namespace)" * doctest::skip(!IsRoot())) {
  RequireTool("unshare", "util-linux");
  REQUIRE_MESSAGE(std::system("unshare -n true 2>/dev/null") == 0, "unshare -n failed as root: no network namespaces here");
  const auto dir = TempDir("no_route");
  const auto scen = WriteScenario(dir, kTiny);
  const auto run = dir / "run";
  // A new network namespace: loopback only, no multicast route.
  const int code = std::system(("unshare -n sh -c 'ip link set lo up; " + std::string(RTHS_BIN_DIR) + "/rths-run " +
                                scen.string() + " --out " + run.string() + "' > " + (dir / "out.txt").string() + " 2>&1")
                                   .c_str());
  std::ifstream in(dir / "out.txt");
  std::string output;
  output.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CAPTURE(output);
  CHECK(WEXITSTATUS(code) == rths::kExitUsage);
  CHECK(output.rfind("rths run: this host has no route for multicast", 0) == 0);
  CHECK(output.find("rths run: rths run:") == std::string::npos);
  CHECK(output.find("ip route add 224.0.0.0/4 dev lo") != std::string::npos);
  CHECK_FALSE(fs::exists(run));
  CHECK(RunCli(scen.string() + " --transport memq --out " + run.string(), &output) == 0);
  CHECK(ReadRunLog((run / "log.lcm").string()).CompleteSteps() == 200);
}

TEST_CASE("a starved host (a busy loop on every core) and tiny socket buffers only slow a run down") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const std::string text = "[run]\nname = \"starved\"\nduration_s = 1.0\n";
  const auto base = TempDir("starve_clean");
  const auto clean = rths::scenario::LoadScenario(WriteScenario(base, text).string());
  REQUIRE(RunMemq({clean}, base).code == 0);

  SUBCASE("busy loops on every core") {
    std::vector<pid_t> spinners;
    const long cores = std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN));
    for (long i = 0; i < cores; ++i) {
      const pid_t p = ::fork();
      if (p == 0) {
        volatile std::uint64_t x = 0;
        for (;;) x = x + 1;
      }
      spinners.push_back(p);
    }
    const auto dir = TempDir("starved");
    std::string output;
    const int code = RunCli(WriteScenario(dir, text).string() + " --out " + (dir / "run").string(), &output);
    for (pid_t p : spinners) ::kill(p, SIGKILL);
    for (pid_t p : spinners) ::waitpid(p, nullptr, 0);
    CAPTURE(output);
    CHECK(code == 0);
    CHECK(Digest(dir / "run") == Digest(base));
  }
  SUBCASE("2 kB receive buffers (LCM's recv_buf_size): bursts overflow, the repair fills the gaps") {
    const auto dir = TempDir("small_buffers");
    std::string output;
    const int code = RunCli(WriteScenario(dir, text + "[lockstep]\nrerequest_ms = 10.0\n[faults]\nrecv_buf_bytes = 2048\n")
                                    .string() + " --out " + (dir / "run").string(),
                            &output);
    CAPTURE(output);
    CHECK(code == 0);
    CHECK(Digest(dir / "run") == Digest(base));
    const auto j = Summary(dir / "run");
    CHECK(j["lcm_url"].get<std::string>().find("recv_buf_size=2048") != std::string::npos);
    MESSAGE("2 kB buffers: " << j["link"]["rerequests"] << " re-requests, " << j["link"]["repaired"]
                             << " messages repaired over " << clean.steps() << " steps");
  }
}
