// A sweep on a real Slurm (issue 28): a one-node cluster started here (tests/slurm/one_node.sh:
// Debian's munged, slurmctld and slurmd, configured in a temp folder, no cgroups), 40 runs in 8
// array tasks through `rths sweep --executor slurm`, the table equal byte for byte to the local
// executor's; one array task cancelled makes its runs fail visibly, and a retry, then --resume,
// complete them. The daemons are stopped whatever happens. Without Slurm, with fake sbatch programs
// on PATH: the job script runs the SPEC's [slurm] setup lines before the command, and a submission
// that fails leaves no output folder.
#include <doctest/doctest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "io/command.h"
#include "sweep/run_sweep.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

const std::string kScript = std::string(RTHS_SOURCE_DIR) + "/tests/slurm/one_node.sh";

/// The cluster of one test; stopped by the destructor.
struct OneNodeSlurm {
  fs::path dir;
  bool up = false;
  std::string log;
  explicit OneNodeSlurm(fs::path d) : dir(std::move(d)) {
    const auto r = rths::io::RunCommand({"/bin/bash", kScript, "start", dir.string()});
    log = r.output;
    up = r.status == 0;
    if (up) ::setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
  }
  ~OneNodeSlurm() {
    rths::io::RunCommand({"/bin/bash", kScript, "stop", dir.string()});
    ::unsetenv("SLURM_CONF");
  }
};

rths::io::CommandResult Sweep(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {std::string(RTHS_BIN_DIR) + "/rths-sweep"};
  argv.insert(argv.end(), args.begin(), args.end());
  return rths::io::RunCommand(argv);
}

/// `rths-sweep args` with `bin` first on PATH (fake sbatch, squeue, scontrol).
rths::io::CommandResult SweepWithPath(const fs::path& bin, const std::vector<std::string>& args) {
  const char* path = std::getenv("PATH");
  std::vector<std::string> argv = {"/usr/bin/env", "PATH=" + bin.string() + ":" + (path ? path : "/usr/bin:/bin"),
                                   std::string(RTHS_BIN_DIR) + "/rths-sweep"};
  argv.insert(argv.end(), args.begin(), args.end());
  return rths::io::RunCommand(argv);
}

/// An executable shell script `dir/name`.
void FakeProgram(const fs::path& dir, const std::string& name, const std::string& body) {
  fs::create_directories(dir);
  std::ofstream(dir / name) << "#!/bin/sh\n" << body;
  fs::permissions(dir / name, fs::perms::owner_all);
}

/// A SPEC of 4 short runs whose [slurm] table ends with `slurm_lines`.
fs::path SmallSpec(const fs::path& dir, const std::string& slurm_lines) {
  fs::create_directories(dir);
  const fs::path base = rths_test::WriteScenario(dir, "[run]\nname = \"sweep_base\"\nduration_s = 0.05\n");
  const fs::path spec = dir / "spec.toml";
  std::ofstream(spec) << "[sweep]\nname = \"fake\"\nbase = \"" << base.string() << "\"\nrecord = [\"steps\"]\n"
                      << "[grid]\n\"controller.kind\" = [\"none\", \"ff\"]\n\"structure.damping_ratio\" = [0.02, 0.05]\n"
                      << "[slurm]\nruns_per_task = 4\n" << slurm_lines;
  return spec;
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_CASE("a sweep on a one-node Slurm: the local table, a cancelled task seen, retried and resumed" *
          doctest::skip(!rths_test::IsRoot())) {
  for (const char* tool : {"munged", "slurmctld", "slurmd"}) {
    REQUIRE_MESSAGE(!rths::io::FindProgram(tool).empty(),
                    tool << " is not installed: apt-get install slurmctld slurmd slurm-client munge "
                            "(scripts/bootstrap.sh --tests installs them)");
  }
  for (const char* tool : {"sbatch", "squeue", "scontrol", "scancel"}) rths_test::RequireTool(tool, "slurm-client");
  rths_test::RequireBuilt("rths-sweep");
  const fs::path dir = rths_test::TempDir("sweep_slurm");
  const fs::path base = rths_test::WriteScenario(dir, "[run]\nname = \"sweep_base\"\nduration_s = 0.05\n");
  const fs::path spec_path = dir / "spec.toml";
  std::ofstream(spec_path) << "[sweep]\nname = \"slurm_ci\"\nbase = \"" << base.string() << "\"\nseed = 11\ndraws = 5\n"
                           << "record = [\"tracking_nrmse_pct\", \"peak_force_kN\", \"steps\", \"status\"]\n"
                           << "[grid]\n\"controller.kind\" = [\"none\", \"ff\"]\n"
                           << "\"structure.damping_ratio\" = [0.02, 0.05, 0.1, 0.2]\n"
                           << "[draw]\n\"plant.noise_seed\" = { dist = \"seed\" }\n"
                           << "\"structure.frequency_hz\" = { dist = \"normal\", mean = 1.0, std = 0.1 }\n"
                           << "[slurm]\nruns_per_task = 5\nretries = 0\n";
  const auto spec = rths::sweep::LoadSpec(spec_path.string());
  REQUIRE(spec.runs() == 40);

  // The local executor's table.
  rths::sweep::SweepOptions local;
  local.out = dir / "local";
  local.jobs = 2;
  auto t0 = std::chrono::steady_clock::now();
  REQUIRE(rths::sweep::RunSweep(spec, local).failed == 0);
  const double local_s = Seconds(t0);
  const std::string local_table = rths_test::Slurp(local.out / "table.csv");

  OneNodeSlurm slurm(dir / "cluster");
  REQUIRE_MESSAGE(slurm.up, "the one-node Slurm did not start: " << slurm.log);

  // 1. The whole sweep, 8 array tasks: the same table, byte for byte.
  t0 = std::chrono::steady_clock::now();
  auto r = Sweep({spec_path.string(), "--executor", "slurm", "--out", (dir / "s1").string(), "--poll-s", "0.2"});
  const double slurm_s = Seconds(t0);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("array tasks 0-7 of 8") != std::string::npos);
  CHECK(rths_test::Slurp(dir / "s1" / "table.csv") == local_table);
  MESSAGE("40 runs: local (2 at a time) " << local_s << " s; Slurm, 8 array tasks on 2 cores " << slurm_s
                                          << " s: about " << (slurm_s - local_s) / 4.0 << " s per task round");

  // 2. Detached; task 7 cancelled before it runs: its five runs have no row, and the collector says so.
  const fs::path s2 = dir / "s2";
  r = Sweep({spec_path.string(), "--executor", "slurm", "--out", s2.string(), "--detach"});
  REQUIRE(r.status == 0);
  const auto state = nlohmann::json::parse(rths_test::Slurp(s2 / "slurm" / "sweep.json"));
  const std::string job = state["jobs"].back().get<std::string>();
  const auto cancel = rths::io::RunCommand({rths::io::FindProgram("scancel"), job + "_7"});
  REQUIRE_MESSAGE(cancel.status == 0, cancel.output);
  r = Sweep({"--collect", s2.string(), "--retries", "0", "--poll-s", "0.2"});
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("array task 7 of job " + job + ": 5 of its 5 runs have no row") != std::string::npos);
  CHECK(r.output.find("runs done 35/40") != std::string::npos);
  // 3. A retry submits task 7 alone and completes the table.
  r = Sweep({"--collect", s2.string(), "--retries", "1", "--poll-s", "0.2"});
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(r.output.find("submitted array tasks 7 again") != std::string::npos);
  CHECK(rths_test::Slurp(s2 / "table.csv") == local_table);
  // 4. Rows lost from task 3: without --resume the folder is refused; with it only task 3 runs.
  fs::remove(s2 / "rows" / "3.json");
  fs::remove(s2 / "rows" / "27.json");
  r = Sweep({spec_path.string(), "--executor", "slurm", "--out", s2.string()});
  CHECK(r.status == 2);
  CHECK(r.output.find("--resume") != std::string::npos);
  r = Sweep({spec_path.string(), "--executor", "slurm", "--out", s2.string(), "--resume", "--poll-s", "0.2"});
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(r.output.find("array tasks 3 of 8") != std::string::npos);
  CHECK(rths_test::Slurp(s2 / "table.csv") == local_table);

  // 5. A task killed while it runs: the rows of the runs it finished stay, the collector names it
  // with Slurm's verdict, and its retry makes only the runs left.
  const fs::path base2 = dir / "long.toml";
  std::ofstream(base2) << "[run]\nname = \"sweep_long\"\nduration_s = 8.0\ncsv_every = 0\n";
  const fs::path spec2_path = dir / "spec2.toml";
  std::ofstream(spec2_path) << "[sweep]\nname = \"slurm_kill\"\nbase = \"" << base2.string() << "\"\nseed = 5\ndraws = 8\n"
                            << "record = [\"tracking_nrmse_pct\", \"peak_force_kN\"]\n"
                            << "[draw]\n\"plant.noise_seed\" = { dist = \"seed\" }\n"
                            << "[slurm]\nruns_per_task = 4\nretries = 0\n";
  const auto spec2 = rths::sweep::LoadSpec(spec2_path.string());
  rths::sweep::SweepOptions local2;
  local2.out = dir / "local2";
  local2.jobs = 2;
  REQUIRE(rths::sweep::RunSweep(spec2, local2).failed == 0);
  const fs::path s3 = dir / "s3";
  r = Sweep({spec2_path.string(), "--executor", "slurm", "--out", s3.string(), "--detach"});
  REQUIRE(r.status == 0);
  const std::string job3 =
      nlohmann::json::parse(rths_test::Slurp(s3 / "slurm" / "sweep.json"))["jobs"].back().get<std::string>();
  // Task 1 runs 1, 3, 5, 7: cancel it once its first row is there.
  bool killed = false;
  for (int i = 0; i < 600 && !killed; ++i) {
    if (fs::exists(s3 / "rows" / "1.json")) {
      killed = rths::io::RunCommand({rths::io::FindProgram("scancel"), job3 + "_1"}).status == 0;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  REQUIRE(killed);
  r = Sweep({"--collect", s3.string(), "--retries", "0", "--poll-s", "0.2"});
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("array task 1 of job " + job3 + ": ") != std::string::npos);
  CHECK(r.output.find("state CANCELLED") != std::string::npos);
  CHECK(fs::exists(s3 / "rows" / "1.json"));  // kept: written when run 1 ended
  int left = 0;
  for (const int i : {3, 5, 7}) left += !fs::exists(s3 / "rows" / (std::to_string(i) + ".json"));
  CHECK(left >= 1);
  r = Sweep({"--collect", s3.string(), "--retries", "1", "--poll-s", "0.2"});
  CHECK(r.status == 0);
  CHECK(rths_test::Slurp(s3 / "table.csv") == rths_test::Slurp(local2.out / "table.csv"));
}

TEST_CASE("a reproduction on Slurm: fig9's runs as a job array give its table byte for byte and every run's log" *
          doctest::skip(!rths_test::IsRoot())) {
  REQUIRE_MESSAGE(!rths::io::FindProgram("slurmctld").empty(),
                  "slurmctld is not installed: apt-get install slurmctld slurmd slurm-client munge");
  rths_test::RequireBuilt("rths-reproduce");
  rths_test::RequireBuilt("rths-sweep");
  const fs::path dir = rths_test::TempDir("reproduce_slurm");
  const std::string reproduce = std::string(RTHS_BIN_DIR) + "/rths-reproduce";
  auto local = rths::io::RunCommand({reproduce, "fig9", "--quick", "--out", (dir / "local").string()});
  REQUIRE_MESSAGE(local.status == 0, local.output);
  OneNodeSlurm slurm(dir / "cluster");
  REQUIRE_MESSAGE(slurm.up, "the one-node Slurm did not start: " << slurm.log);
  auto r = rths::io::RunCommand({reproduce, "fig9", "--quick", "--out", (dir / "slurm").string(), "--executor", "slurm",
                                 "--runs-per-task", "6", "--poll-s", "0.2"});
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("36 runs in 6 array tasks") != std::string::npos);
  CHECK(rths_test::Slurp(dir / "slurm" / "fig9.csv") == rths_test::Slurp(dir / "local" / "fig9.csv"));
  int runs = 0;
  for (const auto& e : fs::directory_iterator(dir / "local" / "runs")) {
    const fs::path other = dir / "slurm" / "runs" / e.path().filename();
    CHECK(rths_test::Slurp(other / "scenario.toml") == rths_test::Slurp(e.path() / "scenario.toml"));
    const auto cmp = rths::io::RunCommand({std::string(RTHS_BIN_DIR) + "/rths-log", "compare",
                                           (e.path() / "log.lcm").string(), (other / "log.lcm").string()});
    CHECK_MESSAGE(cmp.status == 0, e.path().filename().string() << ": " << cmp.output);
    ++runs;
  }
  CHECK(runs == 36);
}

TEST_CASE("the job script runs [slurm] setup's lines in order, quoted, before the command; a failing line stops the task") {
  rths_test::RequireBuilt("rths-sweep");
  const fs::path dir = rths_test::TempDir("sweep_slurm_setup");
  FakeProgram(dir / "bin", "sbatch", "echo 42\n");  // accepts any job: --detach returns at once
  // Line 2 sees line 1's export; line 3 holds quotes and a comment, which must reach bash unchanged.
  const fs::path spec = SmallSpec(dir, R"(setup = ["export RTHS_SETUP_MARK=from-line-1", 'echo "2: $RTHS_SETUP_MARK" > setup.txt', "echo 'three' >> setup.txt  # a comment"]
)");
  const fs::path out = dir / "out";
  auto r = SweepWithPath(dir / "bin", {spec.string(), "--executor", "slurm", "--out", out.string(), "--detach"});
  INFO(r.output);
  REQUIRE(r.status == 0);
  const std::string script = rths_test::Slurp(out / "slurm" / "task.sh");
  INFO(script);
  const std::size_t l1 = script.find("\neval 'export RTHS_SETUP_MARK=from-line-1' ||");
  const std::size_t l2 = script.find("\neval 'echo \"2: $RTHS_SETUP_MARK\" > setup.txt' ||");
  const std::size_t l3 = script.find(R"(
eval 'echo '\''three'\'' >> setup.txt  # a comment' ||)");
  const std::size_t command = script.find("\nexec '");
  REQUIRE(l1 != std::string::npos);
  REQUIRE(l2 != std::string::npos);
  REQUIRE(l3 != std::string::npos);
  REQUIRE(command != std::string::npos);
  CHECK(l1 < l2);
  CHECK(l2 < l3);
  CHECK(l3 < command);
  CHECK(nlohmann::json::parse(rths_test::Slurp(out / "slurm" / "sweep.json"))["setup"].size() == 3);
  // The script as a node runs it (task 0 of 1): the setup's effects, then the runs' rows.
  auto task = rths::io::RunCommand(
      {"/usr/bin/env", "SLURM_ARRAY_TASK_ID=0", "/bin/bash", (out / "slurm" / "task.sh").string()}, out);
  INFO(task.output);
  CHECK(task.status == 0);
  CHECK(rths_test::Slurp(out / "setup.txt") == "2: from-line-1\nthree\n");
  CHECK(fs::exists(out / "rows" / "3.json"));
  // A line that fails stops the task before the command, naming itself.
  const fs::path spec2 = SmallSpec(dir / "two", "setup = [\"true\", \"module_that_is_not_here load gcc/12\"]\n");
  const fs::path out2 = dir / "out2";
  r = SweepWithPath(dir / "bin", {spec2.string(), "--executor", "slurm", "--out", out2.string(), "--detach"});
  REQUIRE(r.status == 0);
  task = rths::io::RunCommand(
      {"/usr/bin/env", "SLURM_ARRAY_TASK_ID=0", "/bin/bash", (out2 / "slurm" / "task.sh").string()}, out2);
  INFO(task.output);
  CHECK(task.status == 1);
  CHECK(task.output.find("rths: [slurm] setup line 2 failed (exit 127): module_that_is_not_here load gcc/12") !=
        std::string::npos);
  CHECK(fs::is_empty(out2 / "rows"));
}

TEST_CASE("a submission that fails leaves no output folder behind") {
  rths_test::RequireBuilt("rths-sweep");
  const fs::path dir = rths_test::TempDir("sweep_slurm_refused");
  FakeProgram(dir / "bin", "sbatch",
              "echo 'sbatch: error: Batch job submission failed: Invalid partition name specified' >&2\nexit 1\n");
  FakeProgram(dir / "garbage", "sbatch", "echo 'Submitted batch job (not --parsable)'\n");
  const fs::path spec = SmallSpec(dir, "partition = \"gpu\"\n");
  for (const fs::path& bin : {dir / "bin", dir / "garbage"}) {
    const fs::path out = dir / "out";
    const auto r = SweepWithPath(bin, {spec.string(), "--executor", "slurm", "--out", out.string()});
    INFO(r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find("sbatch: refused the job array") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
  }
  CHECK(SweepWithPath(dir / "bin", {spec.string(), "--executor", "slurm", "--out", (dir / "out").string()})
            .output.find("Invalid partition name specified") != std::string::npos);
  // A folder that was there stays, without the folders the sweep made in it.
  const fs::path mine = dir / "mine";
  fs::create_directories(mine);
  std::ofstream(mine / "notes.txt") << "mine\n";
  const auto r = SweepWithPath(dir / "bin", {spec.string(), "--executor", "slurm", "--out", mine.string()});
  CHECK(r.status == 2);
  CHECK(fs::exists(mine / "notes.txt"));
  CHECK_FALSE(fs::exists(mine / "rows"));
  CHECK_FALSE(fs::exists(mine / "runs"));
  CHECK_FALSE(fs::exists(mine / "slurm"));
}

TEST_CASE("--dry-run writes the job script and prints the sbatch command, submitting nothing") {
  rths_test::RequireBuilt("rths-sweep");
  const fs::path dir = rths_test::TempDir("sweep_slurm_dry_run");
  // An sbatch that leaves a mark if it is ever called: a dry run must not call it.
  FakeProgram(dir / "bin", "sbatch", "touch \"$0.called\"\necho 42\n");
  const fs::path spec = SmallSpec(dir, "partition = \"short\"\ntime = \"00:10:00\"\nsbatch_args = [\"--qos=low prio\"]\n"
                                       "setup = [\"module load gcc/12\"]\n");
  const fs::path out = dir / "out";
  const auto r = SweepWithPath(dir / "bin", {spec.string(), "--executor", "slurm", "--out", out.string(), "--dry-run",
                                             "--account", "lab1"});
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK_FALSE(fs::exists(dir / "bin" / "sbatch.called"));
  CHECK_FALSE(fs::exists(out / "slurm" / "sweep.json"));
  CHECK(rths_test::Slurp(out / "slurm" / "task.sh").find("\neval 'module load gcc/12' ||") != std::string::npos);
  CHECK(r.output.find("dry run: nothing submitted") != std::string::npos);
  // The command as a shell line: 4 runs at 4 per task are one array task; the flags and the SPEC's
  // [slurm] in order, a value with a space quoted.
  const std::string expected = "sbatch --parsable --job-name=rths-sweep-fake --array=0 --cpus-per-task=1 --output=" +
                               (out / "slurm" / "task-%A_%a.out").string() + " --chdir=" + out.string() +
                               " --partition=short --time=00:10:00 --account=lab1 '--qos=low prio' " +
                               (out / "slurm" / "task.sh").string() + "\n";
  CHECK(r.output.find("\n  " + expected) != std::string::npos);
  // A real submission after it starts afresh.
  const auto real = SweepWithPath(dir / "bin", {spec.string(), "--executor", "slurm", "--out", out.string(), "--detach"});
  INFO(real.output);
  CHECK(real.status == 0);
  CHECK(fs::exists(dir / "bin" / "sbatch.called"));
  // Not for the local executor.
  const auto local = SweepWithPath(dir / "bin", {spec.string(), "--out", (dir / "local").string(), "--dry-run"});
  CHECK(local.status == 2);
  CHECK(local.output.find("--dry-run: is for --executor slurm") != std::string::npos);
}
