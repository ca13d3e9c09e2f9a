// Exports and decoding (issue 13): io::SignalsFromRunLog against the log and signals.csv of a short
// memq run; `rths export` to MATLAB v5 / v7.3 (read back by GNU Octave) and CSV; `rths log dump`;
// the Java types jar.
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/exit_code.h"
#include "io/csv.h"
#include "io/run_log.h"
#include "io/run_signals.h"
#include "scenario/scenario.h"
#include "signal/metrics.h"
#include "run_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace rths_test;

using rths_test::Slurp;

namespace {

// 0.2 s at 2 kHz: 400 steps of the default SDOF scenario (tracking ff, MR damper at 0 A).
const char* kScenario = R"(
[run]
name = "export_test"
duration_s = 0.2
[lockstep]
rerequest_ms = 20.0
stall_budget_s = 5.0
handshake_timeout_s = 5.0
)";

constexpr std::int64_t kSteps = 400;

/// A recorded run (memq, like rths run --transport memq) in a fresh folder, made once per process.
const fs::path& RecordedRun() {
  static const fs::path rec = [] {
    const fs::path dir = TempDir("export");
    const fs::path run = dir / "run";
    fs::create_directories(run);
    WriteScenario(run, kScenario);
    const auto s = rths::scenario::LoadScenario((run / "scenario.toml").string());
    const auto r = RunMemq({s}, run);
    REQUIRE(r.code == 0);
    return run;
  }();
  return rec;
}

struct ToolResult {
  int code = -1;
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

/// Runs `command` with sh; its stdout and stderr are captured apart.
ToolResult Shell(const std::string& command) {
  const fs::path dir = TempDir("shell_out");
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const int status = std::system((command + " > " + out.string() + " 2> " + err.string()).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(out), Slurp(err)};
}

/// Runs build/bin/rths-<tool> ARGS.
ToolResult Tool(const std::string& tool, const std::string& args) {
  return Shell(std::string(RTHS_BIN_DIR) + "/rths-" + tool + " " + args);
}

/// The signals of the recorded run, as rths export decodes them.
const rths::io::RunSignals& RecordedSignals() {
  static const rths::io::RunSignals s = [] {
    const auto log = rths::io::ReadRunLog((RecordedRun() / "log.lcm").string());
    return rths::io::SignalsFromRunLog(log, rths::scenario::LoadScenario((RecordedRun() / "scenario.toml").string()).run.dt_s);
  }();
  return s;
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
double Sum(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m += x;
  return m;
}

/// "key value" lines printed by the Octave script, by key.
std::map<std::string, std::string> KeyValues(const std::string& text) {
  std::map<std::string, std::string> kv;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto sp = line.find(' ');
    if (sp != std::string::npos) kv[line.substr(0, sp)] = line.substr(sp + 1);
  }
  return kv;
}

}  // namespace

TEST_CASE("SignalsFromRunLog: every column, in order, equal to the decoded log and to signals.csv") {
  const fs::path& run = RecordedRun();
  const auto log = rths::io::ReadRunLog((run / "log.lcm").string());
  REQUIRE(log.CompleteSteps() == kSteps);
  const double dt_s = rths::scenario::LoadScenario((run / "scenario.toml").string()).run.dt_s;
  const auto s = rths::io::SignalsFromRunLog(log, dt_s);
  CHECK(s.dt_s == dt_s);
  CHECK(s.steps() == static_cast<std::size_t>(kSteps));

  std::vector<std::string> names;
  for (const auto& c : s.columns) {
    names.push_back(c.name);
    CHECK(c.values.size() == static_cast<std::size_t>(kSteps));
    CHECK_FALSE(c.description.empty());
  }
  const std::vector<std::string> expected{
      "k", "t_s", "r_mm", "rd_mm_s", "rdd_mm_s2", "rddd_mm_s3", "acc_prev_mm_s2", "vel_prev_mm_s",
      "ground_acc_mm_s2", "x1_mm", "abs_acc1_mm_s2", "u_mm", "u_ff_mm", "u_fb_mm", "y_mm", "e_mm",
      "f_kN", "i_eff_A", "i_cmd_A", "f_desired_kN"};
  CHECK(names == expected);
  CHECK(s.At("f_kN").unit == "kN");
  CHECK(s.At("rdd_mm_s2").unit == "mm/s^2");
  CHECK(s.At("k").unit == "");
  CHECK(s.Find("x2_mm") == nullptr);
  try {
    (void)s.At("nope_mm");
    FAIL("At did not throw");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("nope_mm") != std::string::npos);
  }
  CHECK_THROWS_AS(rths::io::SignalsFromRunLog(log, 0.0), rths::Error);

  // Against the decoded messages, exactly.
  for (std::size_t k = 0; k < s.steps(); ++k) {
    CAPTURE(k);
    CHECK(s.At("k").values[k] == static_cast<double>(k));
    CHECK(s.At("r_mm").values[k] == log.desired[k].r_mm);
    CHECK(s.At("rddd_mm_s3").values[k] == log.desired[k].rddd_mm_s3);
    CHECK(s.At("x1_mm").values[k] == log.desired[k].x_mm[0]);
    CHECK(s.At("abs_acc1_mm_s2").values[k] == log.desired[k].abs_acc_mm_s2[0]);
    CHECK(s.At("u_fb_mm").values[k] == log.command[k].u_fb_mm);
    CHECK(s.At("e_mm").values[k] == log.desired[k].r_mm - log.measured[k].y_mm);
    CHECK(s.At("i_eff_A").values[k] == log.measured[k].current_A);
    CHECK(s.At("f_desired_kN").values[k] == log.current[k].f_desired_kN);
  }
  // The run moved: a test of equal zeros would prove nothing.
  double peak_f = 0.0;
  for (double f : s.At("f_kN").values) peak_f = std::max(peak_f, std::abs(f));
  CHECK(peak_f > 0.01);

  // Against the logger's signals.csv: same names, values to the last digit (%.17g), t_s to 1e-6.
  // Rows are matched by k (a logger may write every n-th step only).
  const auto csv = rths::io::ReadCsvFile(run / "signals.csv");
  REQUIRE(csv.size() >= 2);
  const auto& header = csv[0];
  REQUIRE(header[0] == "k");
  for (std::size_t row = 1; row < csv.size(); ++row) {
    const auto k = static_cast<std::size_t>(std::stoll(csv[row][0]));
    REQUIRE(k < s.steps());
    for (std::size_t j = 0; j < header.size(); ++j) {
      CAPTURE(header[j]);
      CAPTURE(k);
      const auto* c = s.Find(header[j]);
      REQUIRE(c != nullptr);
      const double v = std::stod(csv[row][j]);
      if (header[j] == "t_s")
        CHECK(std::abs(v - c->values[k]) <= 1e-6);
      else
        CHECK(v == c->values[k]);
    }
  }
}

TEST_CASE("SignalsFromRunLog: a 9-story structure has x1..x9 and abs_acc1..abs_acc9, in DOF order") {
  const fs::path dir = TempDir("export_mdof");
  const auto sc = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 0.05
[structure]
kind = "file"
file = ")" + std::string(RTHS_SOURCE_DIR) + R"(/data/buildings/ohtori9_ns.txt"
actuator_dof = 1
specimen_count = 18.0
)").string());
  REQUIRE(RunMemq({sc}, dir).code == 0);
  const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
  const auto s = rths::io::SignalsFromRunLog(log, sc.run.dt_s);
  REQUIRE(s.steps() == 100);
  std::vector<std::string> names;
  for (const auto& c : s.columns) names.push_back(c.name);
  const auto at = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
  CHECK(at("ground_acc_mm_s2") + 1 == at("x1_mm"));
  CHECK(at("x9_mm") + 1 == at("abs_acc1_mm_s2"));
  CHECK(at("abs_acc9_mm_s2") + 1 == at("u_mm"));
  CHECK(s.Find("x10_mm") == nullptr);
  for (std::size_t k = 0; k < s.steps(); ++k) {
    CHECK(s.At("x9_mm").values[k] == log.desired[k].x_mm[8]);
    CHECK(s.At("abs_acc5_mm_s2").values[k] == log.desired[k].abs_acc_mm_s2[4]);
  }
  CHECK(MaxAbs(s.At("abs_acc9_mm_s2").values) > 0.0);
}

TEST_CASE("SignalsFromRunLog: a log without a complete step gives empty columns") {
  rths::io::RunLog empty;
  empty.source = "empty.lcm";
  const auto s = rths::io::SignalsFromRunLog(empty, 0.0005);
  CHECK(s.steps() == 0);
  CHECK(s.Find("r_mm") != nullptr);
  CHECK(s.Find("x1_mm") == nullptr);
}

TEST_CASE("rths export: .mat v5 and v7.3 read back by GNU Octave, and CSV, equal to the log") {
  const fs::path& run = RecordedRun();
  const auto& s = RecordedSignals();
  const fs::path dir = TempDir("export_out");
  const fs::path mat5 = dir / "run_v5.mat", mat73 = dir / "run_v73.mat", csv = dir / "run.csv";

  auto r = Tool("export", run.string() + " --mat " + mat5.string() + " --csv " + csv.string());
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("400 steps") != std::string::npos);
  r = Tool("export", run.string() + " --mat " + mat73.string() + " --mat-version 7.3");
  REQUIRE(r.code == 0);
  // Default: RUN_DIR/export.mat.
  r = Tool("export", run.string());
  REQUIRE(r.code == 0);
  CHECK(fs::file_size(run / "export.mat") > 1000);
  // No temporary file left beside the outputs.
  for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);

  // The CSV: the names as header, one row per step, every value exact (shortest round-trip text).
  const auto table = rths::io::ReadCsvFile(csv);
  REQUIRE(table.size() == s.steps() + 1);
  REQUIRE(table[0].size() == s.columns.size());
  for (std::size_t j = 0; j < s.columns.size(); ++j) {
    CHECK(table[0][j] == s.columns[j].name);
    for (std::size_t k = 0; k < s.steps(); ++k) CHECK(std::stod(table[k + 1][j]) == s.columns[j].values[k]);
  }

  RequireTool("octave-cli", "octave");
  // Octave prints key value lines; char() because Octave reads v7.3 strings as uint16 codes.
  for (const fs::path& mat : {mat5, mat73}) {
    CAPTURE(mat);
    const std::string script =
        "d = load('" + mat.string() + "'); r = d.rths; g = r.signals; "
        "printf('numel %d\\n', numel(g.y_mm)); printf('rows %d\\n', size(g.y_mm, 1)); "
        "printf('maxabs_y %.17g\\n', max(abs(g.y_mm))); printf('sum_f %.17g\\n', sum(g.f_kN)); "
        "printf('r_last %.17g\\n', g.r_mm(end)); printf('x1_10 %.17g\\n', g.x1_mm(11)); "
        "printf('unit_f [%s]\\n', char(r.units.f_kN)); printf('unit_acc [%s]\\n', char(r.units.rdd_mm_s2)); "
        "printf('desc_e %s\\n', char(r.descriptions.e_mm)); "
        "printf('names %s\\n', char(r.names)); printf('fields %d\\n', numel(fieldnames(g))); "
        "printf('steps %d\\n', r.meta.steps); printf('dt %.17g\\n', r.meta.dt_s); "
        "printf('run_id %d\\n', r.meta.run_id); printf('complete %d\\n', r.meta.complete); "
        "printf('status %s\\n', char(r.meta.status)); printf('sha %s\\n', char(r.meta.scenario_sha256)); "
        "printf('scenario_has_name %d\\n', numel(strfind(char(r.meta.scenario), 'export_test'))); "
        "printf('end ok\\n');";
    const auto o = Shell("octave-cli --no-gui --norc --eval \"" + script + "\"");
    INFO(o.out, o.err);
    // octave-cli may say "error: ignoring const execution_exception& while preparing to exit" and
    // still exit 0: the exit code and the last line both count.
    REQUIRE(o.code == 0);
    const auto kv = KeyValues(o.out);
    REQUIRE(kv.count("end"));
    CHECK(std::stoll(kv.at("numel")) == static_cast<long long>(s.steps()));
    CHECK(std::stoll(kv.at("rows")) == static_cast<long long>(s.steps()));
    const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
    CHECK(close(std::stod(kv.at("maxabs_y")), MaxAbs(s.At("y_mm").values)));
    CHECK(close(std::stod(kv.at("sum_f")), Sum(s.At("f_kN").values)));
    CHECK(std::stod(kv.at("r_last")) == s.At("r_mm").values.back());
    CHECK(std::stod(kv.at("x1_10")) == s.At("x1_mm").values[10]);
    CHECK(kv.at("unit_f") == "[kN]");
    CHECK(kv.at("unit_acc") == "[mm/s^2]");
    CHECK(kv.at("desc_e") == s.At("e_mm").description);
    CHECK(kv.at("names").rfind("k,t_s,r_mm,", 0) == 0);
    CHECK(std::stoul(kv.at("fields")) == s.columns.size());
    CHECK(std::stoll(kv.at("steps")) == static_cast<long long>(s.steps()));
    CHECK(std::stod(kv.at("dt")) == s.dt_s);
    CHECK(std::stoll(kv.at("run_id")) == rths::io::ReadRunLog((run / "log.lcm").string()).run_id);
    CHECK(kv.at("complete") == "1");
    CHECK(kv.at("status") == "finished");
    CHECK(kv.at("sha").size() == 64);
    CHECK(kv.at("scenario_has_name") == "1");
  }

  // The MATLAB/Octave example examples/matlab/rths_run_summary.m: Eq. 31 as rths computes it.
  const std::string call = "addpath('" + std::string(RTHS_SOURCE_DIR) + "/examples/matlab'); s = rths_run_summary('" +
                           mat5.string() + "'); printf('nrmse %.17g\\npeak_f %.17g\\nend ok\\n', "
                           "s.tracking_nrmse_pct, s.peak_force_kN);";
  const auto o = Shell("octave-cli --no-gui --norc --eval \"" + call + "\"");
  INFO(o.out, o.err);
  REQUIRE(o.code == 0);
  const auto kv = KeyValues(o.out);
  REQUIRE(kv.count("end"));
  const double nrmse = rths::signal::RmsErrorPercent(s.At("r_mm").values, s.At("y_mm").values);
  CHECK(std::stod(kv.at("nrmse")) == doctest::Approx(nrmse).epsilon(1e-12));
  CHECK(std::stod(kv.at("peak_f")) == MaxAbs(s.At("f_kN").values));
  CHECK(o.out.find("tracking error") != std::string::npos);
}

TEST_CASE("rths export: errors name the folder or file; a truncated log exports its complete steps") {
  const fs::path& run = RecordedRun();
  const fs::path dir = TempDir("export_errors");

  // A folder without log.lcm.
  const fs::path empty = dir / "no_log";
  fs::create_directories(empty);
  auto r = Tool("export", empty.string());
  CHECK(r.code == 2);
  CHECK(r.err.find("rths export: " + empty.string() + ": no log.lcm") != std::string::npos);
  CHECK_FALSE(fs::exists(empty / "export.mat"));
  // Not a folder; not a log; a usage error.
  CHECK(Tool("export", (dir / "missing").string()).code == 2);
  const fs::path garbage = dir / "garbage";
  fs::create_directories(garbage);
  std::ofstream(garbage / "log.lcm") << "k,t_s\n0,0\n";
  r = Tool("export", garbage.string());
  CHECK(r.code == 2);
  CHECK(r.err.find("log.lcm") != std::string::npos);
  CHECK(Tool("export", run.string() + " --mat-version 6").code == 2);
  CHECK(Tool("export", "").code == 2);
  // An output that cannot be written.
  r = Tool("export", run.string() + " --mat " + (dir / "nowhere" / "x.mat").string());
  CHECK(r.code == 2);
  CHECK(r.err.find((dir / "nowhere" / "x.mat").string()) != std::string::npos);
  CHECK(r.err.find("No such file or directory") != std::string::npos);

  // A full disk (a file size limit: the writes fail part way, EFBIG): exit 2 naming the file,
  // nothing left behind. matio does not check its writes; rths export does.
  for (const std::string& out : {"--mat " + (dir / "full.mat").string(),
                                 "--mat " + (dir / "full.mat").string() + " --mat-version 7.3",
                                 "--csv " + (dir / "full.csv").string()}) {
    CAPTURE(out);
    r = Shell("bash -c \"trap '' XFSZ; ulimit -f 40; " + std::string(RTHS_BIN_DIR) + "/rths-export " + run.string() +
              " " + out + "\"");
    CHECK(r.code == 2);
    CHECK(r.err.find((dir / "full.").string()) != std::string::npos);
    CHECK(r.err.find("write failed") != std::string::npos);
  }
  r = Shell("bash -c \"trap '' XFSZ; ulimit -f 40; " + std::string(RTHS_BIN_DIR) + "/rths-log dump " +
            (run / "log.lcm").string() + " --csv " + (dir / "full_dump.csv").string() + "\"");
  CHECK(r.code == 2);
  CHECK(r.err.find("full_dump.csv: write failed") != std::string::npos);
  for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().find("full") == std::string::npos);
  // A device that is full: written in place (never replaced by a file), the failure reported.
  if (fs::is_character_file("/dev/full")) {
    r = Tool("export", run.string() + " --csv /dev/full");
    CHECK(r.code == 2);
    CHECK(r.err.find("/dev/full: write failed: No space left on device") != std::string::npos);
    CHECK(Tool("export", run.string() + " --mat /dev/full").code == 2);
    CHECK(fs::is_character_file("/dev/full"));
  }

  // A truncated log: the first 60 % of its bytes.
  const fs::path cut = dir / "cut";
  fs::create_directories(cut);
  fs::copy_file(run / "scenario.toml", cut / "scenario.toml");
  const std::string bytes = Slurp(run / "log.lcm");
  std::ofstream(cut / "log.lcm", std::ios::binary) << bytes.substr(0, bytes.size() * 6 / 10);
  const auto cut_log = rths::io::ReadRunLog((cut / "log.lcm").string());
  REQUIRE_FALSE(cut_log.Complete());
  REQUIRE(cut_log.CompleteSteps() > 0);
  r = Tool("export", cut.string() + " --csv " + (cut / "cut.csv").string() + " --mat " + (cut / "cut.mat").string());
  INFO(r.out, r.err);
  CHECK(r.code == rths::kExitTruncated);  // 12 (3 before issue 45: it collided with kExitLockstep)
  CHECK(r.err.find("truncated") != std::string::npos);
  CHECK(r.err.find("exported its " + std::to_string(cut_log.CompleteSteps()) + " complete steps") != std::string::npos);
  CHECK(fs::exists(cut / "cut.mat"));
  CHECK(rths::io::ReadCsvFile(cut / "cut.csv").size() == static_cast<std::size_t>(cut_log.CompleteSteps()) + 1);
}

TEST_CASE("rths log dump: every message decoded, per channel and all together") {
  const fs::path& run = RecordedRun();
  const auto log = rths::io::ReadRunLog((run / "log.lcm").string());
  const fs::path dir = TempDir("dump");

  // Every channel to stdout: one row per event, counts per channel as in the log.
  auto r = Tool("log", "dump " + (run / "log.lcm").string());
  INFO(r.err);
  REQUIRE(r.code == 0);
  const auto all = rths::io::ParseCsv(r.out);
  REQUIRE(all.size() == static_cast<std::size_t>(log.events) + 1);
  const auto& header = all[0];
  REQUIRE(header.size() > 3);
  CHECK(header[0] == "channel");
  CHECK(header[1] == "k");
  CHECK(header[2] == "run_id");
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    return static_cast<std::size_t>(it - header.begin());
  };
  std::map<std::string, std::int64_t> rows;
  const std::size_t f_col = column("f_kN"), x1_col = column("x1_mm");
  for (std::size_t i = 1; i < all.size(); ++i) {
    REQUIRE(all[i].size() == header.size());
    ++rows[all[i][0]];
    const auto k = std::stoll(all[i][1]);
    if (all[i][0] == "RTHS_MEASURED") CHECK(std::stod(all[i][f_col]) == log.measured[static_cast<std::size_t>(k)].f_kN);
    if (all[i][0] == "RTHS_DESIRED") CHECK(std::stod(all[i][x1_col]) == log.desired[static_cast<std::size_t>(k)].x_mm[0]);
    if (all[i][0] == "RTHS_COMMAND") CHECK(all[i][f_col].empty());
  }
  for (const auto& [ch, n] : log.count) CHECK(rows[ch] == n);
  CHECK(rows["RTHS_HANDSHAKE"] == static_cast<std::int64_t>(log.handshakes.size()));

  // One channel, its fields as columns, into a file.
  const fs::path out = dir / "measured.csv";
  r = Tool("log", "dump " + (run / "log.lcm").string() + " --channel measured --csv " + out.string());
  REQUIRE(r.code == 0);
  const auto measured = rths::io::ReadCsvFile(out);
  CHECK(measured[0] == std::vector<std::string>{"k", "run_id", "y_mm", "f_kN", "current_A"});
  REQUIRE(measured.size() == static_cast<std::size_t>(kSteps) + 1);
  CHECK(std::stod(measured[101][2]) == log.measured[100].y_mm);
  CHECK(std::stoll(measured[101][1]) == log.run_id);

  // Handshakes: phases by name.
  r = Tool("log", "dump " + (run / "log.lcm").string() + " --channel RTHS_HANDSHAKE");
  REQUIRE(r.code == 0);
  CHECK(r.out.find(",GO,") != std::string::npos);
  CHECK(r.out.find(",DONE,") != std::string::npos);

  // Usage errors and bad input: exit 2, named.
  r = Tool("log", "dump " + (run / "log.lcm").string() + " --channel RTHS_ACKX");
  CHECK(r.code == 2);
  CHECK(r.err.find("RTHS_ACKX") != std::string::npos);
  CHECK(Tool("log", "dump").code == 2);
  r = Tool("log", "dump " + (dir / "missing.lcm").string());
  CHECK(r.code == 2);
  CHECK(r.err.find("missing.lcm") != std::string::npos);
}

TEST_CASE("Java types jar: built with the tree, and buildable in a tree configured without Java") {
  RequireTool("javac", "default-jdk-headless");
  RequireTool("jar", "default-jdk-headless");
  RequireFile("/usr/share/java/lcm.jar", "liblcm-java");
  RequireTool("unzip", "unzip");
  // Part of the default build when Java was there at configure time.
  const fs::path jar = fs::path(RTHS_BIN_DIR).parent_path() / "rths_lcmtypes.jar";
  const std::string why = jar.string() + " missing: build the default target (or lcmtypes_jar)";
  REQUIRE_MESSAGE(fs::exists(jar), why);
  const auto list = Shell("unzip -l " + jar.string());
  CHECK(list.out.find("rths/desired_t.class") != std::string::npos);
  CHECK(list.out.find("rths/handshake_t.class") != std::string::npos);

  // MATLAB's way of decoding a log with the jar (docs/export.md), in Octave's JVM.
  RequireTool("octave-cli", "octave");
  {  // INFO's scope
    const fs::path& run = RecordedRun();
    const std::string script =
        "if ~usejava('jvm'); printf('nojvm\\n'); exit(0); end; javaaddpath('/usr/share/java/lcm.jar'); "
        "javaaddpath('" + jar.string() + "'); log = javaObject('lcm.logging.Log', '" + (run / "log.lcm").string() +
        "', 'r'); f = []; while true; try; ev = log.readNext(); catch; break; end; "
        "if strcmp(char(ev.channel), 'RTHS_MEASURED'); m = javaObject('rths.measured_t', ev.data); "
        "f(end+1) = m.f_kN; end; end; log.close(); printf('n %d\\nsum_f %.17g\\nend ok\\n', numel(f), sum(f));";
    const auto o = Shell("octave-cli --no-gui --norc --eval \"" + script + "\"");
    INFO(o.out, o.err);
    REQUIRE_MESSAGE(o.out.find("nojvm") == std::string::npos,
                    "Octave has no JVM: apt-get install default-jdk-headless (scripts/bootstrap.sh --tests installs it)");
    REQUIRE(o.code == 0);
    const auto kv = KeyValues(o.out);
    REQUIRE(kv.count("end"));
    CHECK(std::stoll(kv.at("n")) == kSteps);
    const auto& s = RecordedSignals();
    CHECK(std::stod(kv.at("sum_f")) == doctest::Approx(Sum(s.At("f_kN").values)).epsilon(1e-12));
  }

  // A tree configured as if javac were absent (JAVAC=OFF): the target exists all the same and
  // finds javac when it runs.
  const fs::path tree = TempDir("jar_tree");
  auto r = Shell("cmake -S " + std::string(RTHS_SOURCE_DIR) + " -B " + tree.string() + " -G Ninja -DJAVAC=OFF");
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  r = Shell("cmake --build " + tree.string() + " --target lcmtypes_jar");
  REQUIRE(r.code == 0);
  CHECK(Shell("unzip -l " + (tree / "rths_lcmtypes.jar").string()).out.find("rths/desired_t.class") != std::string::npos);
  fs::remove_all(tree);
}
