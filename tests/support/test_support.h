#pragma once
// Shared by every test: files, temp folders, the rths-run CLI, and one policy for missing tools.
// It includes no rths library, so a test links only the libraries it tests; helpers that need one
// are their own headers (run_support.h, scenario_support.h, udpm_support.h).
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <doctest/doctest.h>


namespace rths_test {

namespace fs = std::filesystem;

/// The whole file as bytes ("" if it cannot be read).
inline std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A CSV cell as a number; NaN unless the whole cell is one.
inline double Number(const std::string& s) {
  double v = std::nan("");
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nan("");
  return v;
}

/// A fresh, empty folder under the system's temp folder, unique to this test process.
inline fs::path TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("rths_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

inline fs::path WriteScenario(const fs::path& dir, const std::string& text) {
  const fs::path p = dir / "scenario.toml";
  std::ofstream(p) << text;
  return p;
}

/// Runs `rths-run ARGS` (the supervisor), its stdout and stderr into `*output`; returns its exit code.
inline int RunCli(const std::string& args, std::string* output = nullptr, const std::string& prefix = "") {
  const fs::path out_txt = fs::temp_directory_path() / ("rths_run_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = prefix + std::string(RTHS_BIN_DIR) + "/rths-run " + args + " > " + out_txt.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  if (output) {
    std::ifstream in(out_txt);
    std::stringstream ss;
    ss << in.rdbuf();
    *output = ss.str();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// One policy for tests that need something outside the build: they fail, naming the Debian package
// that provides it (scripts/bootstrap.sh --tests installs every one, and CI runs it), never pass silently.
// What cannot be had without root is an explicit, counted skip: TEST_CASE(... * doctest::skip(!IsRoot())).

/// Whether `program` is on PATH.
inline bool OnPath(const std::string& program) {
  return std::system(("command -v " + program + " > /dev/null 2>&1").c_str()) == 0;
}

/// Fails the test unless `program` is on PATH; the message names `package`, which installs it.
inline void RequireTool(const std::string& program, const std::string& package) {
  REQUIRE_MESSAGE(OnPath(program), program << " is not installed: apt-get install " << package
                                           << " (scripts/bootstrap.sh --tests installs it)");
}

/// Fails the test unless `file` exists; the message names `package`, which installs it.
inline void RequireFile(const fs::path& file, const std::string& package) {
  REQUIRE_MESSAGE(fs::exists(file), file.string() << " is missing: apt-get install " << package
                                                  << " (scripts/bootstrap.sh --tests installs it)");
}

/// Fails the test unless RTHS_BIN_DIR/`program` is built (the default target builds every program).
inline void RequireBuilt(const std::string& program) {
  const fs::path bin = fs::path(RTHS_BIN_DIR) / program;
  REQUIRE_MESSAGE(::access(bin.c_str(), X_OK) == 0, bin.string() << " is not built: cmake --build build");
}

/// Whether the tests run as root (CI does): mounting a tmpfs and making a network namespace need it.
inline bool IsRoot() { return ::geteuid() == 0; }

}  // namespace rths_test
