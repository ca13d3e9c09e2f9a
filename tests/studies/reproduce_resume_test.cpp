// `rths reproduce` stopped by Ctrl-C and finished with --resume (README "Commands"): the
// interrupted study says what it stopped, every run it started has a summary.json, and --resume
// reuses the runs that ended and gives the tables of an uninterrupted study.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <filesystem>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace fs = std::filesystem;
using rths_test::Slurp;

namespace {

/// rths-reproduce `args` in a shell, its output to `output`; `env` (e.g. "PATH=...") before it.
pid_t Start(const std::string& args, const fs::path& output, const std::string& env = "") {
  const std::string cmd = "exec " + (env.empty() ? std::string() : "env " + env + " ") + std::string(RTHS_BIN_DIR) + "/rths-reproduce " + args + " > " + output.string() + " 2>&1";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

int Wait(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Run folders (those that hold a scenario.toml) under dir/runs, and how many have each status.
struct Folders {
  int runs = 0, with_log = 0, with_summary = 0, completed = 0, interrupted = 0;
};
Folders Count(const fs::path& dir) {
  Folders f;
  if (!fs::exists(dir / "runs")) return f;
  for (const auto& e : fs::recursive_directory_iterator(dir / "runs")) {
    if (e.path().filename() != "scenario.toml") continue;
    const fs::path run = e.path().parent_path();
    ++f.runs;
    f.with_log += fs::exists(run / "log.lcm") ? 1 : 0;
    if (!fs::exists(run / "summary.json")) continue;
    try {
      const auto j = nlohmann::json::parse(Slurp(run / "summary.json"));
      ++f.with_summary;
      f.completed += j.value("status", "") == "completed" ? 1 : 0;
      f.interrupted += j.value("status", "") == "interrupted" ? 1 : 0;
    } catch (const std::exception&) {
    }
  }
  return f;
}

/// fig11.md without its first lines (the command and the wall time).
std::string Tables(const fs::path& md) {
  const std::string text = Slurp(md);
  const auto at = text.find("| controller |");
  REQUIRE(at != std::string::npos);
  return text.substr(at);
}

}  // namespace

TEST_CASE("rths reproduce: Ctrl-C stops the study and says what it stopped; --resume finishes it, same tables") {
  const fs::path dir = rths_test::TempDir("reproduce_resume");
  const std::string common = "fig11 --quick --compact --jobs 2";
  // Interrupted once 3 runs have ended.
  const pid_t pid = Start(common + " --out " + (dir / "a").string(), dir / "a.txt");
  bool enough = false;
  for (int i = 0; i < 1200 && !enough; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    enough = Count(dir / "a").completed >= 3;
  }
  REQUIRE_MESSAGE(enough, Slurp(dir / "a.txt"));
  ::kill(pid, SIGINT);
  const int code = Wait(pid);
  const std::string out = Slurp(dir / "a.txt");
  CAPTURE(out);
  CHECK(code == 130);
  CHECK(out.find("rths reproduce fig11: interrupted: ") != std::string::npos);
  CHECK(out.find("Finish it (the runs that ended are kept): rths reproduce fig11 --out " + (dir / "a").string() +
                 " --quick --resume") != std::string::npos);
  const Folders cut = Count(dir / "a");
  CHECK(cut.completed >= 3);
  CHECK(cut.completed < 12);
  // Every run that started has its summary.json: ended, or interrupted.
  CHECK(cut.with_summary == cut.with_log);
  CHECK(cut.completed + cut.interrupted == cut.with_summary);
  CHECK_FALSE(fs::exists(dir / "a" / "fig11.md"));

  // Resumed with other options: refused, nothing run.
  std::string refused;
  CHECK(Wait(Start("fig11 --compact --jobs 2 --resume --out " + (dir / "a").string(), dir / "r.txt")) == 2);
  CHECK(Slurp(dir / "r.txt").find("hold another scenario than this study makes") != std::string::npos);

  // Resumed: it finishes, keeping the runs that ended.
  REQUIRE_MESSAGE(Wait(Start(common + " --resume --out " + (dir / "a").string(), dir / "b.txt")) == 0,
                  Slurp(dir / "b.txt"));
  const Folders done = Count(dir / "a");
  CHECK(done.completed == 12);
  CHECK(done.interrupted == 0);
  // The same tables as a study never interrupted.
  REQUIRE_MESSAGE(Wait(Start(common + " --out " + (dir / "c").string(), dir / "c.txt")) == 0, Slurp(dir / "c.txt"));
  CHECK(Tables(dir / "a" / "fig11.md") == Tables(dir / "c" / "fig11.md"));
}

/// fig11 --quick with a stand-in gnuplot (`script`, a sh body) first on PATH, then the same study
/// resumed with the real gnuplot. Checks what every interrupt while drawing must give: exit 130,
/// no "gnuplot failed", the resume line; and that the resumed study draws its figures. Returns
/// the interrupted study's output.
std::string InterruptedWhileDrawing(const std::string& name, const std::string& script) {
  const fs::path dir = rths_test::TempDir(name);
  fs::create_directories(dir / "bin");
  const fs::path fake = dir / "bin" / "gnuplot";
  std::ofstream(fake) << "#!/bin/sh\n" << script;
  fs::permissions(fake, fs::perms::owner_all);
  const std::string path = (dir / "bin").string() + ":" + (std::getenv("PATH") ? std::getenv("PATH") : "/usr/bin:/bin");
  const std::string common = "fig11 --quick --compact --jobs 2 --out " + (dir / "a").string();
  const int code = Wait(Start(common, dir / "a.txt", "PATH=" + path));
  const std::string out = Slurp(dir / "a.txt");
  CAPTURE(out);
  CHECK(code == 130);
  CHECK(out.find("gnuplot failed") == std::string::npos);
  CHECK(out.find("Finish it (the runs that ended are kept): rths reproduce fig11 --out " + (dir / "a").string() +
                 " --quick --resume") != std::string::npos);
  // Resumed with the real gnuplot: the figures are drawn, the runs kept.
  REQUIRE_MESSAGE(Wait(Start(common + " --resume", dir / "b.txt")) == 0, Slurp(dir / "b.txt"));
  CHECK(fs::exists(dir / "a" / "fig11.md"));
  return out;
}

TEST_CASE("rths reproduce: Ctrl-C while a figure is drawn is an interrupt too: exit 130 and the resume line") {
  // Ctrl-C reaches gnuplot with the study (one process group): a stand-in that dies of SIGINT as
  // the real one would. Before, this was "gnuplot failed (exit 130)", exit 2.
  const std::string out = InterruptedWhileDrawing("reproduce_plot_interrupt", "kill -INT $$\n");
  CHECK(out.find("gnuplot was interrupted (signal 2)") != std::string::npos);
}

TEST_CASE("rths reproduce: Ctrl-C while gnuplot draws, gnuplot catching it and exiting 1 as the real one does") {
  // The real gnuplot catches SIGINT and exits 1; Ctrl-C reaches the study's process too (one
  // foreground group). Before, this was "gnuplot failed (exit 1)", exit 2, a half-drawn PNG kept
  // and no resume line. The stand-in sends SIGINT to its parent (the study), then exits 1.
  const std::string out =
      InterruptedWhileDrawing("reproduce_plot_interrupt_exit1", "kill -INT $PPID\nsleep 0.2\nexit 1\n");
  CHECK(out.find("interrupted while gnuplot drew") != std::string::npos);
}
