#pragma once
// Shared by the tests of `rths run --external` (external_test, external_liveness_test): start a
// run that waits for the user's participant, read what it printed, run the user's participant
// with the printed values, and wait for the run's summary.
#include <doctest/doctest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "io/run_log.h"
#include "scenario/scenario.h"
#include "run_support.h"
#include "test_support.h"

namespace rths_test {

namespace fs = std::filesystem;

/// The payload digest of the same scenario run in one process (the reference).
inline std::string ReferenceDigest(const fs::path& dir, const fs::path& scenario) {
  const fs::path out = dir / "reference";
  fs::create_directories(out);
  const auto s = rths::scenario::LoadScenario(scenario.string());
  REQUIRE(RunMemq({s}, out).code == 0);
  return rths::io::PayloadDigest(rths::io::ReadRunLog((out / "log.lcm").string()));
}

/// What `rths run --external` printed for the user's participant.
struct PrintedRun {
  std::string url, run_id, scenario;
  pid_t pid = 0;  ///< of the backgrounded `rths run` (its shell's child)
};

/// Starts `rths run --external plant ARGS` (or `command` ARGS, e.g. "rths-replay") in the
/// background (prefix: e.g. "ip netns exec A") and waits for its printed block.
inline PrintedRun StartExternalRun(const fs::path& dir, const std::string& run_args, const std::string& run_prefix = "",
                                   const std::string& command = "rths-run --external plant") {
  const fs::path printed = dir / "run.out";
  const std::string start = run_prefix + " " + std::string(RTHS_BIN_DIR) + "/" + command + " " + run_args +
                            " > " + printed.string() + " 2>&1 & echo $! > " + (dir / "run.pid").string();
  REQUIRE(std::system(("(" + start + ")").c_str()) == 0);
  std::string text;
  for (int i = 0; i < 200 && text.find("waiting up to") == std::string::npos; ++i) {
    ::usleep(50000);
    text = Slurp(printed);
  }
  REQUIRE_MESSAGE(text.find("waiting up to") != std::string::npos, text);
  std::smatch m_url, m_id, m_sc;
  REQUIRE(std::regex_search(text, m_url, std::regex("lcm_url +(\\S+)")));
  REQUIRE(std::regex_search(text, m_id, std::regex("run_id +([0-9]+)")));
  REQUIRE(std::regex_search(text, m_sc, std::regex("scenario +(\\S+)")));
  PrintedRun r{m_url[1].str(), m_id[1].str(), m_sc[1].str()};
  r.pid = static_cast<pid_t>(std::stol(Slurp(dir / "run.pid")));
  return r;
}

/// Whether process `pid` (not our child) has exited: gone, or a zombie its new parent has not
/// reaped yet (that can take a while).
inline bool Exited(pid_t pid) {
  if (::kill(pid, 0) != 0) return true;
  const std::string stat = Slurp("/proc/" + std::to_string(pid) + "/stat");
  const std::size_t close = stat.rfind(')');
  return close == std::string::npos || stat.compare(close + 2, 1, "Z") == 0;
}

/// Waits (at most 60 s) for the backgrounded run to exit; its summary.json in `out`.
inline nlohmann::json WaitExternalRun(const PrintedRun& run, const fs::path& out) {
  for (int i = 0; i < 600 && !Exited(run.pid); ++i) ::usleep(100000);
  return nlohmann::json::parse(Slurp(out / "summary.json"));
}

/// The built-in plant as the user's participant: rths-plant with the printed values.
inline std::string BuiltInPlant(const std::string& url, const std::string& run_id, const std::string& scenario,
                                const fs::path& out, const std::string& extra = "") {
  return std::string(RTHS_BIN_DIR) + "/rths-plant --scenario " + scenario + " --lcm-url '" + url + "' --run-id " +
         run_id + " --out " + out.string() + " " + extra;
}

/// Starts `rths run --external plant ARGS` in the background (prefix: e.g. "ip netns exec A"),
/// waits for its printed block, then runs the user's plant with the printed URL and run id
/// (plant_prefix, and URL rewritten by `fix_url`); returns the run's exit code.
/// `plant_cmd` (optional): the user's plant command for (url, run id, scenario); default rths-plant.
using PlantCommand = std::function<std::string(const std::string&, const std::string&, const std::string&)>;
inline int RunWithExternalPlant(const fs::path& dir, const std::string& run_args, const std::string& run_prefix,
                                const std::string& plant_prefix, const std::string& plant_url_override = "",
                                const PlantCommand& plant_cmd = {}) {
  const PrintedRun run = StartExternalRun(dir, run_args, run_prefix);
  const std::string url = plant_url_override.empty() ? run.url : plant_url_override;
  const std::string program =
      plant_cmd ? plant_cmd(url, run.run_id, run.scenario) : BuiltInPlant(url, run.run_id, run.scenario, dir);
  const std::string plant = plant_prefix + " timeout 60 " + program + " > " + (dir / "plant.out").string() + " 2>&1";
  std::system(plant.c_str());
  return WaitExternalRun(run, dir / "out")["exit_code"].get<int>();
}

/// Runs the linear servo without a specimen (0.5 s, 1000 steps) with `plant` as the external
/// plant, and in one process with the built-in plant; checks the run completed (else shows what
/// the plant printed), its log is complete, f is 0 and the current the same in both, and the
/// actuator moves; returns the peak |y difference| over the run [mm].
inline double ExternalLinearPlantDeviation(const fs::path& dir, const std::string& name, const PlantCommand& plant) {
  const fs::path scenario = WriteScenario(dir, "[run]\nname = \"" + name +
                                                   "\"\nduration_s = 0.5\n[plant]\nkind = \"linear\"\nactuator = "
                                                   "\"avg\"\nspecimen = \"none\"\n");
  const fs::path ref = dir / "reference";
  fs::create_directories(ref);
  REQUIRE(RunMemq({rths::scenario::LoadScenario(scenario.string())}, ref).code == 0);
  const int code = RunWithExternalPlant(dir, "--join-timeout-s 60 --out " + (dir / "out").string() + " " +
                                                 scenario.string(),
                                        "", "", "", plant);
  REQUIRE_MESSAGE(code == 0, "the plant said:\n" << Slurp(dir / "plant.out"));
  const auto j = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  CHECK(j["participants"]["plant"]["external"] == true);
  const auto a = rths::io::ReadRunLog((ref / "log.lcm").string());
  const auto b = rths::io::ReadRunLog((dir / "out" / "log.lcm").string());
  REQUIRE(b.Complete());
  REQUIRE(b.CompleteSteps() == 1000);
  double peak_dy = 0, peak_y = 0;
  for (std::int64_t k = 0; k < 1000; ++k) {
    peak_dy = std::max(peak_dy, std::abs(a.measured[k].y_mm - b.measured[k].y_mm));
    peak_y = std::max(peak_y, std::abs(a.measured[k].y_mm));
    CHECK(b.measured[k].f_kN == 0.0);
    CHECK(b.measured[k].current_A == a.measured[k].current_A);
  }
  CHECK(peak_y > 0.1);  // the test moves the actuator
  return peak_dy;
}

/// A network namespace pair joined by a veth pair, removed on destruction (even if a check fails).
struct NetnsPair {
  std::string a, b, va, vb;
  bool ok = false;
  NetnsPair() {
    const std::string id = std::to_string(::getpid() % 100000);
    a = "rthsA" + id;
    b = "rthsB" + id;
    va = "rva" + id;
    vb = "rvb" + id;
    const int oct = 1 + ::getpid() % 250;
    const std::string net = "10.213." + std::to_string(oct) + ".";
    const std::string cmd =
        "set -e; ip netns add " + a + "; ip netns add " + b + "; ip link add " + va + " type veth peer name " + vb +
        "; ip link set " + va + " netns " + a + "; ip link set " + vb + " netns " + b +
        "; ip -n " + a + " addr add " + net + "1/24 dev " + va + "; ip -n " + b + " addr add " + net + "2/24 dev " + vb +
        "; for n in " + a + " " + b + "; do ip -n $n link set lo up; done; ip -n " + a + " link set " + va +
        " up multicast on; ip -n " + b + " link set " + vb + " up multicast on; ip -n " + a +
        " route add 224.0.0.0/4 dev " + va + "; ip -n " + b + " route add 224.0.0.0/4 dev " + vb;
    ok = std::system(("bash -c '" + cmd + "' 2>" + ErrorFile().string()).c_str()) == 0;
  }
  /// Why the pair could not be made (for a failed ok).
  static std::string Error() {
    return "cannot create network namespaces and a veth pair (needs root / CAP_NET_ADMIN): " + Slurp(ErrorFile());
  }
  static fs::path ErrorFile() { return fs::temp_directory_path() / "rths_netns.err"; }
  ~NetnsPair() {
    std::system(("ip netns del " + a + " 2>/dev/null; ip netns del " + b + " 2>/dev/null").c_str());
  }
};

}  // namespace rths_test
