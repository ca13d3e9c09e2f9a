// rths replay: a recorded run fed step by step into live participants (the absent ones answer
// from the record, in lockstep), and the comparison of the live outputs with the recording.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "io/log_compare.h"
#include "io/run_log.h"
#include "core/exit_code.h"
#include "lockstep/protocol.h"
#include "participants/replay.h"
#include "scenario/scenario.h"
#include "follow_replay.h"
#include "rths/measured_t.hpp"
#include "run_support.h"
#include "udpm_support.h"
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
fs::path Record(const fs::path& dir, double duration_s = 0.5) {
  const fs::path rec = dir / "recorded";
  fs::create_directories(rec);
  std::string text = kScenario;
  text.replace(text.find("duration_s = 0.5"), 16, fmt::format("duration_s = {:.1f}", duration_s));
  const fs::path scenario = WriteScenario(dir, text);
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

/// What the test's own listener heard on RTHS_MEASURED: the payload of each step (run_id zeroed,
/// as io::RunLog keeps it), with a deep queue and receive buffer of its own.
class MeasuredListener {
 public:
  MeasuredListener(const std::string& url, std::int64_t n_steps) : lcm_(url + "&recv_buf_size=4194304"), got_(n_steps) {
    REQUIRE(lcm_.good());
    lcm_.subscribe(rths::lockstep::kChMeasured, &MeasuredListener::OnMessage, this)->setQueueCapacity(1000000);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(50);
    });
  }
  ~MeasuredListener() { Stop(); }
  void Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  const std::vector<std::vector<std::uint8_t>>& got() const { return got_; }

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (m_.decode(rbuf->data, 0, rbuf->data_size) < 0 || m_.k < 0 || m_.k >= static_cast<std::int64_t>(got_.size())) return;
    m_.run_id = 0;
    rths::lockstep::Encode(m_, &got_[static_cast<std::size_t>(m_.k)]);
  }
  lcm::LCM lcm_;
  std::vector<std::vector<std::uint8_t>> got_;
  rths::measured_t m_{};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Whether step k is listed in one of the ledger's ranges of `key`.
bool InRanges(const nlohmann::json& follow, const char* key, std::int64_t k) {
  for (const auto& r : follow.at(key)) {
    if (k >= r[0].get<std::int64_t>() && k <= r[1].get<std::int64_t>()) return true;
  }
  return false;
}

TEST_CASE("follow mode under CPU load: lcm-logplayer at speed 1 into rths-plant --follow, once, no retry") {
  if (!UdpmAvailable()) FAIL("udpm cannot run on this host: " << rths::lockstep::CheckMulticastRoute());
  RequireTool("lcm-logplayer", "liblcm-bin");
  const auto dir = TempDir("follow_load");
  const fs::path rec = Record(dir, 5.0);
  const auto record = rths::io::ReadRunLog((rec / "log.lcm").string());
  const std::int64_t n = record.CompleteSteps();
  REQUIRE(n == 10000);
  const std::string url = "udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() * 7) % 20000) + "?ttl=0";
  MeasuredListener heard(url, n);
  rths_test::FollowResult r;
  {
    // Every core busy for the whole replay (docs/replay.md: the deep queue is for this).
    const rths_test::BusyLoops busy(static_cast<int>(std::thread::hardware_concurrency()));
    r = rths_test::PlayFollow({RTHS_BIN_DIR, rec, dir / "live", record.run_id, url, 1.0, "--follow-idle-s 1"});
  }
  heard.Stop();
  CAPTURE(r.printed);
  REQUIRE(r.follow.is_object());
  const auto exact = r.follow["exact"].get<std::int64_t>(), held = r.follow["held"].get<std::int64_t>(),
             resumed = r.follow["resumed"].get<std::int64_t>(), unseen = r.follow["unseen"].get<std::int64_t>();
  MESSAGE("follow under load, speed 1: " << exact << " exact, " << held << " held, " << resumed << " resumed, "
                                         << unseen << " unseen of " << n);
  CHECK(exact + held + resumed + unseen == n);
  CHECK(r.follow["n_steps"] == n);
  // What it printed is what it wrote, and its exit code says whether every step was exact.
  CHECK(r.printed.find(fmt::format("follow: run {}, {} steps: {} exact, {} held, {} resumed after a hold, {} unseen",
                                   record.run_id, n, exact, held, resumed, unseen)) != std::string::npos);
  CHECK(r.exit_code == (exact == n ? 0 : rths::kExitFollowInexact));
  // The feed ran to its end: the plant saw the last step.
  CHECK(unseen == 0);
  // Every exact step the listener heard is the recorded answer, bit for bit; a held one is listed.
  const auto& recorded = record.payload.at("RTHS_MEASURED");
  std::int64_t compared = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto& got = heard.got()[static_cast<std::size_t>(k)];
    if (got.empty()) continue;
    const bool listed = InRanges(r.follow, "held_steps", k) || InRanges(r.follow, "resumed_steps", k);
    if (!listed) {
      CHECK(got == recorded[static_cast<std::size_t>(k)]);
      ++compared;
    }
  }
  MESSAGE("the test's listener heard " << compared << " exact answers, all as recorded");
  CHECK(compared > n / 2);
}

TEST_CASE("follow mode: nothing of the run heard is exit 11, and said; the logger and the clock cannot follow") {
  const auto dir = TempDir("follow_silent");
  const fs::path rec = Record(dir);
  const std::string url = "udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() * 7 + 3) % 20000) + "?ttl=0";
  const std::string plant = std::string(RTHS_BIN_DIR) + "/rths-plant --follow --follow-start-s 0.3 --scenario " +
                            (rec / "scenario.toml").string() + " --lcm-url '" + url + "' --out " + dir.string();
  const std::string out = (dir / "plant.out").string();
  int status = std::system((plant + " --run-id 12345 > " + out + " 2>&1").c_str());
  CHECK(WEXITSTATUS(status) == rths::kExitFollowInexact);
  std::string text = Slurp(out);
  CAPTURE(text);
  // Step 0 needs no input (at rest): answered, as recorded; nothing else.
  CHECK(text.find("follow: run 12345, 1000 steps: 1 exact, 0 held, 0 resumed after a hold, 999 unseen") !=
        std::string::npos);
  CHECK(text.find("heard nothing of run 12345") != std::string::npos);
  const auto j = ReadJson(dir / "logs" / "plant.json");
  CHECK(j["exit_code"] == rths::kExitFollowInexact);
  CHECK(j["follow"]["unseen"] == 999);
  CHECK(j["follow"]["messages"] == 0);
  for (const char* role : {"logger", "integrator"}) {
    status = std::system((std::string(RTHS_BIN_DIR) + "/rths-" + role + " --follow --scenario " +
                          (rec / "scenario.toml").string() + " --lcm-url '" + url + "' --run-id 1 > " + out + " 2>&1")
                             .c_str());
    CHECK(WEXITSTATUS(status) == rths::kExitUsage);
    CHECK(Slurp(out).find("--follow: ") != std::string::npos);
  }
}
