#pragma once
// A run with an external plant, for the benches (bench-realtime, bench-lockstep): `rths-run
// --external plant` with a fixed URL and run id in the background, the plant command once the
// run waits for it, then the run's end. The plant is given as a command template.
#include <signal.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

namespace rths_bench {

namespace fs = std::filesystem;

/// The plants a bench can run as external participants: command templates with {bin} (the
/// build's bin folder), {url}, {run_id}, {scenario}, {steps}, {dt}, {out}.
inline const std::map<std::string, std::string>& ExternalPlants() {
  static const std::map<std::string, std::string> plants = {
      {"builtin", "{bin}/rths-plant --scenario {scenario} --lcm-url '{url}' --run-id {run_id} --out {out}/plant"},
      {"java", "java -cp /usr/share/java/lcm.jar:{bin}/../rths_lcmtypes.jar:{bin}/../examples/java_plant JavaPlant "
               "--lcm-url '{url}' --run-id {run_id} --scenario {scenario} --steps {steps} --dt {dt}"},
      {"python", "env PYTHONPATH={bin}/../examples/python_plant /usr/bin/python3 {bin}/../../examples/python_plant/plant.py "
                 "--lcm-url '{url}' --run-id {run_id} --scenario {scenario}"},
  };
  return plants;
}

/// Runs `{bin}/rths-run RUN_ARGS --external plant --lcm-url URL --run-id ID --out OUT SCENARIO`
/// with `plant` (a key of ExternalPlants()) as the plant, started behind `plant_prefix` (e.g.
/// "chrt -f 70"); the run's exit code (its summary is in OUT/summary.json), or -1 if the plant is
/// unknown or the run never waited for it.
inline int RunWithExternalPlant(const fs::path& bin, const std::string& run_args, const fs::path& scenario,
                                const fs::path& out, const std::string& plant, std::int64_t steps, double dt,
                                int port, const std::string& plant_prefix = "") {
  const auto it = ExternalPlants().find(plant);
  if (it == ExternalPlants().end()) return -1;
  fs::remove_all(out);
  fs::create_directories(out.parent_path());
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", port);
  const std::int64_t run_id = 1 + 2 * static_cast<std::int64_t>(::getpid()) + port;
  const fs::path printed = out.string() + ".stdout.txt", pid_file = out.string() + ".pid";
  const std::string start =
      fmt::format("({}/rths-run {} --external plant --join-timeout-s 60 --lcm-url '{}' --run-id {} --out {} {} > {} "
                  "2>&1 & echo $! > {})",
                  bin.string(), run_args, url, run_id, out.string(), scenario.string(), printed.string(),
                  pid_file.string());
  if (std::system(start.c_str()) != 0) return -1;
  std::string text;
  for (int i = 0; i < 400 && text.find("waiting up to") == std::string::npos; ++i) {
    ::usleep(25000);
    std::ifstream in(printed);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  if (text.find("waiting up to") == std::string::npos) return -1;
  const std::string cmd = fmt::format(fmt::runtime(it->second), fmt::arg("bin", bin.string()), fmt::arg("url", url),
                                      fmt::arg("run_id", run_id), fmt::arg("scenario", scenario.string()),
                                      fmt::arg("steps", steps), fmt::arg("dt", dt), fmt::arg("out", out.string()));
  std::system((plant_prefix + " " + cmd + " > " + out.string() + ".plant.txt 2>&1").c_str());
  pid_t pid = 0;
  std::ifstream(pid_file) >> pid;
  for (int i = 0; i < 6000 && pid > 0 && ::kill(pid, 0) == 0; ++i) ::usleep(10000);
  try {
    std::ifstream in(out / "summary.json");
    return nlohmann::json::parse(in).at("exit_code").get<int>();
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace rths_bench
