// The command-line convention of every `rths <sub>` (tools/cli.h, README "Commands"): usage errors
// exit 2, --help exits 0 and names the command as the user types it, options show their defaults;
// --set overrides scenario keys (checked like the file); --compact and run.csv_every shrink the
// output; identify writes plots only where told.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <doctest/doctest.h>

#include "core/progress.h"
#include "io/run_log.h"
#include "scenario/scenario.h"
#include "supervisor/run_summary.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using rths_test::TempDir;

/// Runs `cd CWD && RTHS_BIN_DIR/rths-TOOL ARGS`, stdout and stderr into *output; returns the exit code.
int RunTool(const std::string& tool, const std::string& args, std::string* output, const fs::path& cwd = {}) {
  const fs::path txt = fs::temp_directory_path() / ("rths_cli_" + std::to_string(::getpid()) + ".txt");
  std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-" + tool + " " + args + " > " + txt.string() + " 2>&1";
  if (!cwd.empty()) cmd = "cd '" + cwd.string() + "' && " + cmd;
  const int status = std::system(cmd.c_str());
  std::ifstream in(txt);
  std::stringstream ss;
  ss << in.rdbuf();
  *output = ss.str();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Scenario(const std::string& name) { return std::string(RTHS_SOURCE_DIR) + "/scenarios/" + name; }

long Lines(const fs::path& file) {
  std::ifstream in(file);
  long n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

const char* const kTools[] = {"run",    "design",    "identify", "reproduce",     "diagnose", "record",
                              "replay", "structure", "log",      "utfsm-convert", "export",   "report",
                              "compare", "watch"};

}  // namespace

TEST_CASE("every command: a usage error exits 2, --help exits 0 and shows `rths <sub>`") {
  for (const char* tool : kTools) {
    CAPTURE(tool);
    std::string out;
    CHECK(RunTool(tool, "--no-such-option", &out) == 2);
    CHECK(out.find("Run with --help") != std::string::npos);
    CHECK(out.find(std::string("rths ") + tool + ": ") != std::string::npos);  // one prefix style
    CHECK(RunTool(tool, "--help", &out) == 0);
    CHECK(out.find(std::string("rths ") + tool) != std::string::npos);
    CHECK(out.find("bin/rths-") == std::string::npos);  // not the build path
  }
}

TEST_CASE("options show their defaults and units") {
  std::string out;
  REQUIRE(RunTool("diagnose", "--help", &out) == 0);
  const auto at = out.find("--none-ratio");
  REQUIRE(at != std::string::npos);
  CHECK(out.find("=1.6", at) < out.find("--smooth-hz", at));  // the default, on its own line
  REQUIRE(RunTool("identify", "--help", &out) == 0);
  CHECK(out.find("--band TEXT=0.5-40") != std::string::npos);
  CHECK(out.find("}=inverse-variance") != std::string::npos);
  REQUIRE(RunTool("reproduce", "--help", &out) == 0);
  CHECK(out.find("--jobs") != std::string::npos);
  CHECK(out.find("--set") != std::string::npos);
}

TEST_CASE("scenario::ApplyOverrides: dotted keys, TOML values, bare words, new tables") {
  const std::string text = "[run]\nname = \"x\"\nduration_s = 1.0\n";
  const std::string out = rths::scenario::ApplyOverrides(
      text, {"run.duration_s=5", "controller.kind=ff_lqg", "plant.noise_y_mm_rms = 0.01", "run.name=\"y.z\""}, "t.toml");
  const auto s = rths::scenario::ParseScenario(out, "t.toml");
  CHECK(s.run.duration_s == 5.0);
  CHECK(s.run.name == "y.z");
  CHECK(s.controller.kind == rths::control::ControllerKind::kFfLqg);
  CHECK(s.plant.noise_y_mm_rms == 0.01);
  CHECK_THROWS_WITH_AS(rths::scenario::ApplyOverrides(text, {"run.duration_s"}, "t.toml"),
                       doctest::Contains("expected KEY=VALUE"), rths::Error);
  CHECK_THROWS_WITH_AS(rths::scenario::ApplyOverrides(text, {"run.name.first=1"}, "t.toml"),
                       doctest::Contains("not a table"), rths::Error);
  CHECK_THROWS_WITH_AS(rths::scenario::ApplyOverrides(text, {"run..x=1"}, "t.toml"),
                       doctest::Contains("empty part"), rths::Error);
}

TEST_CASE("--set is checked like the file and names itself in the error") {
  std::string out;
  CHECK(RunTool("design", Scenario("default.toml") + " --set controller.kind=ff_lqg", &out) == 0);
  CHECK(out.find("controller: ff_lqg") != std::string::npos);
  CHECK(RunTool("design", Scenario("default.toml") + " --set run.dt_s=-1", &out) == 2);
  CHECK(out.find("run.dt_s") != std::string::npos);
  CHECK(out.find("(set by --set run.dt_s=-1)") != std::string::npos);
  CHECK(RunTool("design", Scenario("default.toml") + " --set controller.kindd=ff", &out) == 2);
  CHECK(out.find("unknown key") != std::string::npos);
  CHECK(out.find("(set by --set controller.kindd=ff)") != std::string::npos);
  CHECK(RunTool("design", Scenario("default.toml") + " --set foo.bar=1", &out) == 2);  // an unknown table
  CHECK(out.find("foo: unknown table") != std::string::npos);
  CHECK(out.find("(set by --set foo.bar=1)") != std::string::npos);
  CHECK(RunTool("design", Scenario("default.toml") + " --set faults.drop=0.2 --set faults.delay=0.2 --set faults.reorder=0.2",
                &out) == 2);  // a sum over keys: every --set of the table
  CHECK(out.find("= 0.6: the sum must not exceed 0.5") != std::string::npos);
  CHECK(out.find("(set by --set faults.drop=0.2, --set faults.delay=0.2, --set faults.reorder=0.2)") != std::string::npos);
  // reproduce: checked on every run of the study before any runs, naming the run.
  const fs::path dir = TempDir("cli_reproduce_set");
  CHECK(RunTool("reproduce", "fig7 --quick --plant linear --set run.dt_s=0.3 --out " + (dir / "f7").string(), &out) == 2);
  CHECK(out.find("fig7 None: run.dt_s: 0.3 is out of range") != std::string::npos);
  CHECK(out.find("(set by --set run.dt_s=0.3)") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "f7" / "runs"));
  CHECK(RunTool("reproduce", "fig5 --set run.dt_s=0.001 --out " + (dir / "f5").string(), &out) == 2);
}

TEST_CASE("rths run --set and --compact: the scenario that ran is in the folder; no signals.csv") {
  const fs::path dir = TempDir("cli_compact");
  std::string out;
  const int code = RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --compact --set run.duration_s=0.25 --out " +
                                      (dir / "run").string(),
                           &out);
  INFO(out);
  REQUIRE(code == 0);
  CHECK(out.find("output           0.") != std::string::npos);  // the size, said up front (exact: no CSV)
  CHECK(out.find("no signals.csv") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "run" / "signals.csv"));
  const auto log = rths::io::ReadRunLog((dir / "run" / "log.lcm").string());
  CHECK(log.Complete());
  CHECK(log.CompleteSteps() == 500);  // 0.25 s at 0.5 ms
  // The folder's scenario.toml is the one that ran: the overrides are in it.
  const auto s = rths::scenario::LoadScenario((dir / "run" / "scenario.toml").string());
  CHECK(s.run.duration_s == 0.25);
  CHECK(s.run.csv_every == 0);
  // The CSV a compact run left out can be made where it would have been (nothing is replaced).
  CHECK(RunTool("export", (dir / "run").string() + " --csv " + (dir / "run" / "signals.csv").string(), &out) == 0);
  CHECK(Lines(dir / "run" / "signals.csv") == 1 + 500);

  // run.csv_every = 10: a row for k = 0, 10, ..., 490 after the header.
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --set run.duration_s=0.25 --set run.csv_every=10 --out " +
                             (dir / "every10").string(),
                  &out) == 0);
  CHECK(Lines(dir / "every10" / "signals.csv") == 1 + 50);
  CHECK(rths::io::ReadRunLog((dir / "every10" / "log.lcm").string()).CompleteSteps() == 500);
}

TEST_CASE("identify writes a plot only where told") {
  const fs::path dir = TempDir("cli_identify");
  std::string out;
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --compact --set run.duration_s=3 --out " +
                             (dir / "run").string(),
                  &out) == 0);
  REQUIRE(RunTool("record", (dir / "run").string(), &out) == 0);
  const fs::path cwd = dir / "cwd";
  fs::create_directories(cwd);
  const int code = RunTool("identify", (dir / "run" / "record.csv").string() + " --band 0.5-20", &out, cwd);
  INFO(out);
  CHECK(code == 0);
  CHECK(fs::is_empty(cwd));  // no identify.png dropped into the current folder
  CHECK(out.find("no plot") != std::string::npos);
  REQUIRE(RunTool("identify", (dir / "run" / "record.csv").string() + " --band 0.5-20 --out " + (dir / "model.toml").string(),
                  &out, cwd) == 0);
  CHECK(fs::file_size(dir / "model.png") > 10000);  // beside --out
  CHECK(fs::is_empty(cwd));
  std::vector<std::string> names;  // the picture only: no gnuplot data or script beside it
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  CHECK(names == std::vector<std::string>{"cwd", "model.png", "model.toml", "run"});
}

TEST_CASE("progress: drawn with an ETA on a terminal, nothing when the output is not one") {
  CHECK(rths::ProgressLine::FormatSeconds(3.25) == "3.2 s");
  CHECK(rths::ProgressLine::FormatSeconds(42) == "42 s");
  CHECK(rths::ProgressLine::FormatSeconds(185) == "3 min 05 s");
  CHECK(rths::ProgressLine::FormatSeconds(3725) == "1 h 02 min");
  const fs::path dir = TempDir("cli_progress");
  // 60000 steps: at memq's 90k steps/s still over half a second, a few redraws.
  const std::string run = std::string(RTHS_BIN_DIR) + "/rths-run " + Scenario("default.toml") +
                          " --transport memq --skip-space-check --compact --set run.duration_s=30 --out ";
  std::string out;
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --compact --set run.duration_s=10 --out " +
                             (dir / "pipe").string(),
                  &out) == 0);
  CHECK(out.find("\033[K") == std::string::npos);  // not a terminal: no progress line
  // On a terminal (a pseudo-terminal from script(1)): the line, redrawn in place, with the step.
  rths_test::RequireTool("script", "bsdutils");
  const fs::path txt = dir / "tty.txt";
  const std::string cmd = "env -u RTHS_NO_PROGRESS script -qc \"" + run + (dir / "tty").string() + "\" /dev/null > " + txt.string();
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::ifstream in(txt);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string tty = ss.str();
  CHECK(tty.find("\r\033[Krths run ") != std::string::npos);
  CHECK(tty.find(" of 60000") != std::string::npos);
  CHECK(tty.find("tracking error") != std::string::npos);  // the summary after it, on a clean line
}

TEST_CASE("no output replaces what a run recorded or the file being read") {
  const fs::path dir = TempDir("cli_guard");
  const fs::path run = dir / "run";
  std::string out;
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --set run.duration_s=2.5 --out " +
                             run.string(),
                  &out) == 0);
  const auto digest = [&] {
    std::string d;
    for (const char* f : {"log.lcm", "scenario.toml", "summary.json", "signals.csv"}) {
      std::ifstream in(run / f, std::ios::binary);
      d += std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }
    return d;
  };
  const std::string before = digest();
  const std::string log = (run / "log.lcm").string();
  struct Case {
    const char* tool;
    std::string args, says;
  };
  const std::vector<Case> cases = {
      {"log", "dump " + log + " --csv " + log, "is the input"},
      {"log", "dump " + log + " --csv " + (run / "." / "log.lcm").string(), "is the input"},
      {"export", run.string() + " --csv " + log, "is the input"},
      {"export", run.string() + " --mat " + (run / "scenario.toml").string(), "is the input"},
      {"export", run.string() + " --csv " + (run / "signals.csv").string(), "would replace the signals.csv"},
      {"export", run.string() + " --mat " + (dir / "x.csv").string(), "did you mean --csv?"},
      {"export", run.string() + " --csv " + (dir / "x.mat").string(), "did you mean --mat?"},
      {"record", run.string() + " --out " + log, "is the input"},
      {"identify", log + " --out " + (run / "scenario.toml").string(), "would replace the scenario.toml"},
      {"identify", log + " --plot " + (run / "summary.json").string(), "would replace the summary.json"},
      {"utfsm-convert", log + " --out " + log, "is the input"},
      {"diagnose", "--train a.csv --test b.csv --out " + run.string(), "output folder exists and is not empty"},
      {"run", Scenario("default.toml") + " --transport memq --out " + log, "is a file, not a folder"},
      {"run", run.string() + " --transport memq", "is a folder, not a scenario file"},
      {"report", log, "is a file, not a run folder: give the folder that holds log.lcm (here " + run.string() + ")"},
      {"export", log, "is a file, not a run folder"},
      {"record", log, "is a file, not a run folder"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.tool);
    CAPTURE(c.args);
    CHECK(RunTool(c.tool, c.args, &out) == 2);
    CHECK(out.find(c.says) != std::string::npos);
    CHECK(out.find(std::string("rths ") + c.tool + ": ") != std::string::npos);
  }
  CHECK(digest() == before);  // every recorded byte is still there
  CHECK_FALSE(fs::exists(dir / "x.csv"));
  CHECK_FALSE(fs::exists(dir / "x.mat"));
}

TEST_CASE("small frictions: the folder to give, the role meant, the --set meant, no Eq. 31 of no step") {
  const fs::path dir = TempDir("cli_frictions");
  std::string out;
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --compact --quiet --set "
                                                    "run.duration_s=0.05 --out " + (dir / "run").string(),
                  &out) == 0);
  // rths replay RUN/log.lcm: the folder is what it takes, and it says which.
  CHECK(RunTool("replay", (dir / "run" / "log.lcm").string() + " --live plant", &out) == 2);
  CHECK(out.find("is a file, not a run folder: give the folder that holds log.lcm (here " + (dir / "run").string() +
                 ")") != std::string::npos);
  CHECK(out.find("log.lcm/log.lcm") == std::string::npos);
  // A mistyped role: named once, with the one meant.
  CHECK(RunTool("replay", (dir / "run").string() + " --live plnt", &out) == 2);
  CHECK(out.find("rths replay: --live: unknown role 'plnt'; did you mean plant? (live roles: integrator, controller, "
                 "plant, semiactive)") != std::string::npos);
  // An option that is a scenario key: the --set line it means.
  CHECK(RunTool("run", "--duration 5", &out) == 2);
  CHECK(out.find("rths run: --duration is not an option; to change the scenario's run.duration_s: --set "
                 "run.duration_s=5") != std::string::npos);
  CHECK(RunTool("design", Scenario("default.toml") + " --dt_s=0.001", &out) == 2);
  CHECK(out.find("--set run.dt_s=0.001") != std::string::npos);
  // A run in which no step completed prints no tracking error of 0 %.
  rths::supervisor::RunSummary never;
  never.steps = 0;
  never.steps_expected = 100;
  never.metrics = rths::io::RunMetrics{};
  const std::string report = never.Report(0.0005);
  CHECK(report.find("0.000 %") == std::string::npos);
  CHECK(report.find("tracking error     - (no step completed)") != std::string::npos);
  CHECK(report.find("signals.csv's writer") == std::string::npos);
  // A logger that had to wait for its CSV writer says so (summary.json: output_stalls).
  rths::participants::Outcome logger;
  logger.role = "logger";
  logger.output_stalls = 3;
  never.participants.push_back(logger);
  CHECK(never.Report(0.0005).find("  output             3 step(s) waited for signals.csv's writer thread") !=
        std::string::npos);
}

TEST_CASE("design of an identified model file: at the record's step, on the file's own actuator") {
  // A 1 kHz record, identified, then designed: the file carries dt, and G_yr is evaluated on its
  // [plant] actuator, not on the paper's three models.
  const fs::path dir = TempDir("cli_design_model");
  std::string out;
  REQUIRE(RunTool("run", Scenario("default.toml") + " --transport memq --skip-space-check --compact --set run.dt_s=0.001 "
                                                    "--set run.duration_s=4 --out " + (dir / "run").string(),
                  &out) == 0);
  REQUIRE(RunTool("record", (dir / "run").string(), &out) == 0);
  REQUIRE_MESSAGE(RunTool("identify", (dir / "run" / "record.csv").string() + " --band 0.5-20 --out " +
                                          (dir / "model.toml").string(),
                          &out) == 0,
                  out);
  CHECK(rths::scenario::LoadScenario((dir / "model.toml").string()).run.dt_s == 0.001);
  REQUIRE_MESSAGE(RunTool("design", (dir / "model.toml").string(), &out) == 0, out);
  CHECK(out.find("dt = 0.001 s") != std::string::npos);
  CHECK(out.find("the scenario's [plant] actuator (custom, ZOH)") != std::string::npos);
  CHECK(out.find("2.5A") == std::string::npos);  // not the paper's models
}
