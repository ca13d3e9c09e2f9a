// rths replay: a recorded run fed step by step into live participants (the absent ones answer
// from the record, in lockstep), and the comparison of the live outputs with the recording.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "io/log_compare.h"
#include "io/run_log.h"
#include "participants/replay.h"
#include "scenario/scenario.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace rths_test;

namespace {

const char* kScenario = R"(
[run]
name = "replay_test"
duration_s = 0.5
[lockstep]
rerequest_ms = 20.0
stall_budget_s = 2.0
handshake_timeout_s = 5.0
)";

/// Runs `rths-replay ARGS`; its output into *output; returns its exit code.
int Replay(const std::string& args, std::string* output) {
  const fs::path txt = fs::temp_directory_path() / ("rths_replay_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-replay " + args + " > " + txt.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(txt);
  std::stringstream ss;
  ss << in.rdbuf();
  *output = ss.str();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json ReadJson(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

/// A recorded run (memq, like rths run --transport memq) in dir/recorded.
fs::path Record(const fs::path& dir) {
  const fs::path rec = dir / "recorded";
  fs::create_directories(rec);
  const fs::path scenario = WriteScenario(dir, kScenario);
  fs::copy_file(scenario, rec / "scenario.toml");
  const auto s = rths::scenario::LoadScenario((rec / "scenario.toml").string());
  REQUIRE(RunMemq({s}, rec).code == 0);
  return rec;
}

}  // namespace

TEST_CASE("CompareChannel: identical logs, and a perturbed field found with its step, RMS and peak") {
  const auto dir = TempDir("compare");
  const fs::path rec = Record(dir);
  const auto a = rths::io::ReadRunLog((rec / "log.lcm").string());
  const std::int64_t n = a.CompleteSteps();
  REQUIRE(n == 1000);
  for (const char* ch : {"RTHS_DESIRED", "RTHS_COMMAND", "RTHS_MEASURED", "RTHS_CURRENT"}) {
    const auto d = rths::io::CompareChannel(a, a, ch, n);
    CHECK(d.identical());
    CHECK(d.steps == n);
  }
  auto b = a;
  b.measured[5].y_mm += 1.0;
  b.payload["RTHS_MEASURED"][5].back() ^= 1;  // the bytes differ too
  const auto d = rths::io::CompareChannel(a, b, "RTHS_MEASURED", n);
  CHECK_FALSE(d.identical());
  CHECK(d.first_difference == 5);
  CHECK(d.differing_steps == 1);
  REQUIRE(d.fields.size() == 3);
  CHECK(d.fields[0].name == "y_mm");
  CHECK(d.fields[0].peak == doctest::Approx(1.0));
  CHECK(d.fields[0].peak_step == 5);
  CHECK(d.fields[0].rms == doctest::Approx(std::sqrt(1.0 / static_cast<double>(n))));
  CHECK(d.fields[1].peak == 0.0);
  CHECK(rths::io::Describe(d).find("differs from step 5") != std::string::npos);
  CHECK_THROWS(rths::io::CompareChannel(a, b, "RTHS_ACK", n));
}

TEST_CASE("replay: every role live, alone, reproduces the recording bit for bit") {
  const auto dir = TempDir("each");
  const fs::path rec = Record(dir);
  const auto record = rths::io::ReadRunLog((rec / "log.lcm").string());
  const auto s = rths::scenario::LoadScenario((rec / "scenario.toml").string());
  for (const char* role : {"integrator", "controller", "plant", "semiactive"}) {
    CAPTURE(role);
    const fs::path out = dir / role;
    fs::create_directories(out);
    const auto outcomes = rths::participants::RunReplay(s, record, record.CompleteSteps(), {role}, 77, out.string());
    for (const auto& o : outcomes) CHECK(o.exit_code == 0);
    const auto replay = rths::io::ReadRunLog((out / "log.lcm").string());
    CHECK(replay.Complete());
    // Every channel: the live one recomputed, the others replayed.
    CHECK(rths::io::PayloadDigest(replay) == rths::io::PayloadDigest(record));
  }
}

TEST_CASE("rths replay --live plant: the recorded scenario reproduces measured_t bit for bit") {
  const auto dir = TempDir("cli_same");
  const fs::path rec = Record(dir);
  std::string out;
  REQUIRE(Replay(rec.string() + " --live plant --out " + (dir / "replay").string(), &out) == 0);
  CHECK(out.find("RTHS_MEASURED: identical over 1000 steps") != std::string::npos);
  const auto j = ReadJson(dir / "replay" / "replay.json");
  CHECK(j["identical"] == true);
  CHECK(j["channels"]["RTHS_MEASURED"]["identical"] == true);
  CHECK(j["channels"]["RTHS_MEASURED"]["steps_compared"] == 1000);
  const auto a = rths::io::ReadRunLog((rec / "log.lcm").string());
  const auto b = rths::io::ReadRunLog((dir / "replay" / "log.lcm").string());
  CHECK(a.payload.at("RTHS_MEASURED") == b.payload.at("RTHS_MEASURED"));
  // --steps: only the first N.
  REQUIRE(Replay(rec.string() + " --live plant,controller --steps 100 --out " + (dir / "first100").string(), &out) == 0);
  CHECK(ReadJson(dir / "first100" / "replay.json")["steps_replayed"] == 100);
}

TEST_CASE("rths replay --live plant with a changed parameter: reported different, with numbers") {
  const auto dir = TempDir("cli_changed");
  const fs::path rec = Record(dir);
  const fs::path changed = dir / "changed.toml";
  std::ofstream(changed) << kScenario << "\n[plant]\nactuator = \"0.0A\"\n";
  std::string out;
  REQUIRE(Replay(rec.string() + " --live plant --scenario " + changed.string() + " --out " + (dir / "replay").string(),
                 &out) == 1);
  CHECK(out.find("scenario differs from the recorded one") != std::string::npos);
  CHECK(out.find("RTHS_MEASURED: differs from step") != std::string::npos);
  const auto j = ReadJson(dir / "replay" / "replay.json");
  CHECK(j["identical"] == false);
  const auto& m = j["channels"]["RTHS_MEASURED"];
  CHECK(m["first_difference_step"].get<std::int64_t>() >= 1);
  CHECK(m["differing_steps"].get<std::int64_t>() > 0);
  CHECK(m["fields"]["y_mm"]["rms"].get<double>() > 0.0);
  CHECK(m["fields"]["y_mm"]["peak"].get<double>() >= m["fields"]["y_mm"]["rms"].get<double>());
  CHECK(m["fields"]["f_kN"]["peak"].get<double>() > 0.0);
  // The replay itself ran to the end: the recorded controller and integrator do not react.
  CHECK(j["steps_replayed"] == 1000);
}

TEST_CASE("rths replay: bad input is refused before anything runs") {
  const auto dir = TempDir("cli_bad");
  const fs::path rec = Record(dir);
  std::string out;
  CHECK(Replay(rec.string() + " --live pump --out " + (dir / "a").string(), &out) == 2);
  CHECK(out.find("integrator, controller, plant, semiactive") != std::string::npos);
  CHECK(Replay(rec.string() + " --live logger --out " + (dir / "b").string(), &out) == 2);
  CHECK(out.find("always runs its own logger") != std::string::npos);
  {  // a scenario at another step: the step-by-step comparison would be meaningless
    std::ifstream in(rec / "scenario.toml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find("[run]\n");  // the recording ran at the default 0.0005 s
    REQUIRE(at != std::string::npos);
    text.insert(at + 6, "dt_s = 0.001\n");
    std::ofstream(dir / "dt.toml") << text;
    CHECK(Replay(rec.string() + " --live plant --scenario " + (dir / "dt.toml").string() + " --out " +
                     (dir / "e").string(),
                 &out) == 2);
    CHECK(out.find("but the recording ran at 0.0005 s") != std::string::npos);
    CHECK(!fs::exists(dir / "e"));
  }
  CHECK(Replay((dir / "nothing").string() + " --live plant --out " + (dir / "c").string(), &out) == 2);
  CHECK(out.find((dir / "nothing").string() + ": no such run folder (give the folder `rths run` printed") !=
        std::string::npos);
  CHECK(Replay(rec.string() + " --live plant --steps 5000 --out " + (dir / "d").string(), &out) == 2);
  CHECK(out.find("--steps") != std::string::npos);
  // Never overwrites: an existing, non-empty output folder is refused.
  CHECK(Replay(rec.string() + " --live plant --out " + rec.string(), &out) == 2);
  CHECK(out.find("refusing to overwrite") != std::string::npos);
}

TEST_CASE("follow mode: lcm-logplayer drives a live plant (rths-plant --follow); measured_t as recorded") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  const auto dir = TempDir("follow");
  const fs::path rec = Record(dir);
  const auto record = rths::io::ReadRunLog((rec / "log.lcm").string());
  // lcm-logplayer never waits for its listeners (LCM drops silently): on a loaded machine a
  // datagram can be lost, and then the plant stops answering there. The replay is slowed down
  // and retried; what arrives must be bit-identical every time.
  bool complete = false;
  for (int attempt = 0; attempt < 3 && !complete; ++attempt) {
    const std::string url =
        "udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() * 7 + attempt) % 20000) + "?ttl=0";
    const fs::path live = dir / ("live" + std::to_string(attempt) + ".lcm");
    const std::string cmd =
        "cd " + dir.string() + " && (lcm-logger --lcm-url='" + url + "' -f " + live.string() +
        " > /dev/null 2>&1 & echo $! > logger.pid) && sleep 0.5 && (timeout 60 " + std::string(RTHS_BIN_DIR) +
        "/rths-plant --follow --follow-idle-s 1 --scenario " + (rec / "scenario.toml").string() + " --lcm-url '" + url +
        "' --run-id " + std::to_string(record.run_id) + " --out " + dir.string() + " > plant.out 2>&1 & echo $! > plant.pid) && " +
        "sleep 0.5 && lcm-logplayer --speed=0.25 -e '^RTHS_(DESIRED|COMMAND|CURRENT)$' --lcm-url='" + url + "' " +
        (rec / "log.lcm").string() + " > /dev/null 2>&1; wait_for() { while kill -0 $1 2>/dev/null; do sleep 0.1; done; }; " +
        "wait_for $(cat plant.pid); sleep 0.3; kill -INT $(cat logger.pid); wait_for $(cat logger.pid)";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const auto replayed = rths::io::ReadRunLog(live.string());
    REQUIRE(replayed.payload.count("RTHS_MEASURED"));
    const auto& got = replayed.payload.at("RTHS_MEASURED");
    std::int64_t same = 0;
    for (std::size_t k = 0; k < got.size() && k < record.payload.at("RTHS_MEASURED").size(); ++k) {
      if (got[k].empty()) continue;
      CHECK(got[k] == record.payload.at("RTHS_MEASURED")[k]);
      ++same;
    }
    complete = same == record.CompleteSteps();
  }
  CHECK(complete);
}
