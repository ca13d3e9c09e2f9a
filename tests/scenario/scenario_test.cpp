// Tests for lib/scenario: the default file, defaults, hashing, and one case per class of bad input.
#include "scenario/scenario.h"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "models/structure_file.h"
#include "signal/history.h"
#include "scenario_support.h"
#include "test_support.h"

namespace fs = std::filesystem;
using rths::scenario::LoadScenario;
using rths::scenario::ParseScenario;
using rths::scenario::Scenario;

namespace {

const fs::path kSourceDir = RTHS_SOURCE_DIR;

/// The message of the rths::Error that parsing `text` throws ("" and a failed check if none).
std::string ErrorOf(std::string_view text, const std::string& path = "bad.toml") {
  const std::string message = rths_test::ParseError(text, path);
  if (message.empty()) FAIL_CHECK("expected an rths::Error for:\n" << text);
  return message;
}

/// Checks that `message` contains every one of `parts`.
void CheckContains(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (std::string_view part : parts) {
    CHECK_MESSAGE(message.find(part) != std::string::npos, "\"" << part << "\" not in: " << message);
  }
}

/// A fresh empty folder under the system temp dir.
fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rths_scenario_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteFile(const fs::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace

TEST_CASE("the default scenario file loads with the issue's values") {
  const Scenario s = LoadScenario((kSourceDir / "scenarios/default.toml").string());
  CHECK(s.run.dt_s == 0.0005);
  CHECK(s.run.duration_s == 20.0);
  CHECK(s.steps() == 40000);
  CHECK(s.structure.mode == rths::models::StructureMode::kRths);
  CHECK(s.structure.mass_kg == 20000.0);
  CHECK(s.structure.frequency_hz == 5.0);
  CHECK(s.structure.damping_ratio == 0.02);
  CHECK(s.structure.ground.kind == rths::signal::SignalKind::kBlwn);
  CHECK(s.structure.ground.band_hz == 30.0);
  CHECK(s.structure.ground.rms == 1500.0);
  CHECK(s.structure.ground.seed == 1);
  CHECK(s.controller.kind == rths::control::ControllerKind::kFf);
  CHECK(s.controller.model.name == "avg");
  CHECK(s.controller.model.K == 1.600e7);
  CHECK(s.plant.actuator.name == "avg");
  CHECK(s.plant.actuator.p == 151.7);
  CHECK(s.plant.specimen == rths::models::Specimen::kMrDamper);
  CHECK(s.semiactive.mode == rths::control::SemiactiveMode::kPassiveOff);
  CHECK(s.semiactive.current_A == 0.0);
  CHECK(s.sha256.size() == 64);
  CHECK(s.path.find("default.toml") != std::string::npos);
}

TEST_CASE("the tracking scenarios are predefined 0-5 Hz records") {
  for (const char* kind : {"ff", "none"}) {
    CAPTURE(kind);
    const Scenario s = LoadScenario((kSourceDir / "scenarios" / (std::string("tracking_") + kind + "_0-5hz.toml")).string());
    CHECK(s.structure.mode == rths::models::StructureMode::kPredefined);
    CHECK(s.structure.desired.kind == rths::signal::SignalKind::kBlwn);
    CHECK(s.structure.desired.band_hz == 5.0);
    CHECK(s.structure.desired.rms == 2.78);
    CHECK(s.run.duration_s == 60.0);
    CHECK(s.plant.actuator.name == "avg");
    CHECK(s.plant.specimen == rths::models::Specimen::kNone);
    CHECK(rths::NameOf(rths::control::kControllerKindNames, s.controller.kind) == kind);
  }
}

TEST_CASE("every file in scenarios/ loads") {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kSourceDir / "scenarios")) {
    if (entry.path().extension() != ".toml") continue;
    CAPTURE(entry.path().string());
    CHECK_NOTHROW(LoadScenario(entry.path().string()));
    ++count;
  }
  CHECK(count >= 3);
}

TEST_CASE("omitted keys keep the struct defaults") {
  const Scenario empty = ParseScenario("[run]\nname = \"run\"\n", "minimal.toml");  // one key, at its default
  const Scenario defaults;
  CHECK(empty.run.name == defaults.run.name);
  CHECK(empty.run.dt_s == defaults.run.dt_s);
  CHECK(empty.structure.mass_kg == defaults.structure.mass_kg);
  CHECK(empty.structure.desired.band_hz == 5.0);
  CHECK(empty.structure.desired.rms == 2.78);
  CHECK(empty.plant.noise_seed == 7);
  CHECK(empty.plant.ode_rtol == 1e-8);
  CHECK(empty.lockstep.stall_budget_s == 10.0);
  CHECK(empty.sha256.empty());

  const Scenario partial = ParseScenario(R"(
[run]
dt_s = 0.001
[structure.ground]
rms_mm_s2 = 900
)",
                                         "partial.toml");
  CHECK(partial.run.dt_s == 0.001);
  CHECK(partial.run.duration_s == 20.0);
  CHECK(partial.steps() == 20000);
  CHECK(partial.structure.ground.rms == 900.0);  // integer accepted for a float
  CHECK(partial.structure.ground.band_hz == 30.0);
  CHECK(partial.structure.frequency_hz == 5.0);
}

TEST_CASE("servo models: presets and inline tables") {
  const auto a = rths::models::ServoPreset("0.0A");
  CHECK(a.K == 1.730e7);
  CHECK(a.p == 182.7);
  CHECK(a.b == 225.3);
  CHECK(a.c == 9.499e4);
  const auto b = rths::models::ServoPreset("2.5A");
  CHECK(b.K == 1.613e7);
  CHECK(b.p == 134.2);
  CHECK(b.b == 324.6);
  CHECK(b.c == 1.211e5);
  CHECK_THROWS_AS(rths::models::ServoPreset("1.0A"), rths::Error);

  const Scenario s = ParseScenario(R"(
[controller]
model = {K = 1.5e7, p = 150, b = 250.0, c = 1.0e5}
[plant]
actuator = "2.5A"
)",
                                   "servo.toml");
  CHECK(s.controller.model.name == "custom");
  CHECK(s.controller.model.K == 1.5e7);
  CHECK(s.controller.model.p == 150.0);
  CHECK(s.plant.actuator.name == "2.5A");
  CHECK(s.plant.actuator.c == 1.211e5);
}

TEST_CASE("sha256 of known strings") {
  using rths::scenario::Sha256Hex;
  CHECK(Sha256Hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(Sha256Hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST_CASE("LoadScenario hashes exactly the file's bytes") {
  const fs::path dir = TempDir("hash");
  const std::string text = "[run]\r\nname = \"crlf\"\r\n";
  WriteFile(dir / "crlf.toml", text);
  const Scenario s = LoadScenario((dir / "crlf.toml").string());
  CHECK(s.sha256 == rths::scenario::Sha256Hex(text));
  CHECK(s.run.name == "crlf");
  fs::remove_all(dir);
}

TEST_CASE("unknown keys and tables are named, with the allowed ones and a suggestion") {
  CheckContains(ErrorOf("[plant]\nnoise_y_mm = 0.1\n"),
                {"bad.toml: plant.noise_y_mm: unknown key", "actuator", "specimen", "noise_y_mm_rms",
                 "did you mean \"plant.noise_y_mm_rms\""});
  CheckContains(ErrorOf("[run]\ndt = 0.001\n"), {"bad.toml: run.dt: unknown key", "did you mean \"run.dt_s\""});
  CheckContains(ErrorOf("[structure.ground]\nrms_mm = 3.0\n"),
                {"structure.ground.rms_mm: unknown key", "did you mean \"structure.ground.rms_mm_s2\""});
  CheckContains(ErrorOf("[structure.desired]\nrms_mm_s2 = 3.0\n"),
                {"structure.desired.rms_mm_s2: unknown key", "rms_mm"});
  CheckContains(ErrorOf("[controler]\nkind = \"ff\"\n"),
                {"bad.toml: controler: unknown table", "run", "lockstep", "did you mean \"controller\""});
  CheckContains(ErrorOf("[structure.grond]\nkind = \"zero\"\n"),
                {"bad.toml: structure.grond: unknown table", "ground", "desired"});
  CheckContains(ErrorOf("[plant]\nactuator = {K = 1.0e7, p = 150, b = 250, c = 1.0e5, d = 1}\n"),
                {"bad.toml: plant.actuator.d: unknown key", "K, p, b, c"});
  CheckContains(ErrorOf("name = \"x\"\n"), {"bad.toml: name: unknown key", "run, structure"});
}

TEST_CASE("wrong types name the key, the expected type and what was found") {
  CheckContains(ErrorOf("[run]\ndt_s = \"0.001\"\n"),
                {"bad.toml: run.dt_s: expected a number", "found string \"0.001\""});
  CheckContains(ErrorOf("[faults]\nseed = 2.5\n"), {"bad.toml: faults.seed: expected an integer", "found float 2.5"});
  CheckContains(ErrorOf("[controller]\nhalf_step_ahead = \"yes\"\n"),
                {"controller.half_step_ahead: expected a boolean", "found string"});
  CheckContains(ErrorOf("[structure]\nmode = 1\n"), {"structure.mode: expected a string", "found integer 1"});
  CheckContains(ErrorOf("run = 3\n"), {"bad.toml: run: expected a table", "found integer 3"});
  CheckContains(ErrorOf("[plant]\nactuator = 3.5\n"),
                {"plant.actuator: expected a preset name", "found float 3.5"});
  CheckContains(ErrorOf("[plant]\nnoise_seed = -1\n"), {"plant.noise_seed: -1 is out of range [0,"});
}

TEST_CASE("out-of-range values name the key, the value and the range") {
  CheckContains(ErrorOf("[run]\ndt_s = 0.5\n"), {"bad.toml: run.dt_s: 0.5 is out of range [1e-05, 0.01]"});
  CheckContains(ErrorOf("[run]\nduration_s = 0\n"), {"bad.toml: run.duration_s: 0 is out of range (0, 36000]"});
  CheckContains(ErrorOf("[structure]\nmass_kg = -5\n"), {"structure.mass_kg: -5 is out of range (0, 1000000000]"});
  CheckContains(ErrorOf("[structure]\ndamping_ratio = 1.0\n"), {"structure.damping_ratio: 1 is out of range [0, 1)"});
  CheckContains(ErrorOf("[structure]\ndamping_ratio = nan\n"), {"structure.damping_ratio: nan is out of range"});
  CheckContains(ErrorOf("[plant]\node_rtol = 0.1\n"), {"plant.ode_rtol: 0.1 is out of range (0, 0.01]"});
  // The old name (until issue 45) is checked as the new one.
  CheckContains(ErrorOf("[plant]\ncvode_rtol = 0.1\n"), {"plant.ode_rtol: 0.1 is out of range (0, 0.01]"});
  CheckContains(ErrorOf("[plant]\nnoise_f_kN_rms = 200\n"), {"plant.noise_f_kN_rms: 200 is out of range [0, 100]"});
  CheckContains(ErrorOf("[lockstep]\nrerequest_ms = 1\n"), {"lockstep.rerequest_ms: 1 is out of range [5, 10000]"});
  CheckContains(ErrorOf("[lockstep]\nstall_budget_s = 0.5\n"),
                {"lockstep.stall_budget_s: 0.5 is out of range [1, 3600]", "at least 1 s and 4 lockstep.rerequest_ms"});
  CheckContains(ErrorOf("[lockstep]\nrerequest_ms = 2000\nstall_budget_s = 5\n"),
                {"lockstep.stall_budget_s: 5 is out of range [8, 3600]"});
  CheckContains(ErrorOf("[lockstep]\ntimeout_ms = 250\n"), {"lockstep.timeout_ms: was renamed lockstep.rerequest_ms"});
  CheckContains(ErrorOf("[lockstep]\nmax_attempts = 8\n"), {"lockstep.max_attempts: was replaced by lockstep.stall_budget_s"});
  CheckContains(ErrorOf("[faults]\ndrop = 0.6\n"), {"faults.drop: 0.6 is out of range [0, 0.5]"});
  CheckContains(ErrorOf("[faults]\ndrop = 0.3\ndelay = 0.3\n"),
                {"faults: drop + duplicate + delay + reorder = 0.3 + 0 + 0.3 + 0 = 0.6: the sum must not exceed 0.5"});
  CheckContains(ErrorOf("[faults]\nrecv_buf_bytes = 100\n"), {"faults.recv_buf_bytes: 100 is out of range [1024, 134217728]"});
  CheckContains(ErrorOf("[faults.process]\nrole = \"plant\"\nkind = \"explode\"\n"),
                {"faults.process.kind: \"explode\" is not allowed", "\"stop\""});
  CheckContains(ErrorOf("[faults.process]\nrole = \"plan\"\nkind = \"kill\"\n"), {"faults.process.role: \"plan\" is not allowed"});
  CheckContains(ErrorOf("[run]\nduration_s = 1\n[faults.process]\nrole = \"plant\"\nkind = \"kill\"\nat_step = 2000\n"),
                {"faults.process.at_step: 2000 is out of range [0, 2000)"});
  CheckContains(ErrorOf("[lockstep]\nhandshake_timeout_s = 1000\n"),
                {"lockstep.handshake_timeout_s: 1000 is out of range [0.1, 600]"});
  CheckContains(ErrorOf("[semiactive]\nmode = \"constant\"\ncurrent_A = 3.0\n"),
                {"semiactive.current_A: 3 is out of range [0, 2.5]", "max_current_A"});
  CheckContains(ErrorOf("[semiactive]\nmax_current_A = 6\n"), {"semiactive.max_current_A: 6 is out of range (0, 5]"});
  CheckContains(ErrorOf("[structure.desired]\ndiscard_s = 100\n"),
                {"structure.desired.discard_s: 100 is out of range [0, 60]"});
  CheckContains(ErrorOf("[structure.ground]\nrms_mm_s2 = 0\n"), {"structure.ground.rms_mm_s2: 0 is out of range (0,"});
  CheckContains(ErrorOf("[controller]\nmodel = {K = 1.0e7, p = -150, b = 250, c = 1.0e5}\n"),
                {"controller.model.p: -150 is out of range (0, inf)"});
  CheckContains(ErrorOf("[controller]\nmodel = {K = 1.0e7, p = 150, b = 250}\n"),
                {"controller.model.c: missing", "K, p, b, c"});
}

TEST_CASE("limits that depend on dt: central-difference stability and Nyquist") {
  // dt = 0.01 s: 1/(pi dt) = 31.83 Hz, Nyquist 50 Hz.
  CHECK_NOTHROW(ParseScenario("[run]\ndt_s = 0.01\n[structure]\nfrequency_hz = 31.8\n", "ok.toml"));
  CheckContains(ErrorOf("[run]\ndt_s = 0.01\n[structure]\nfrequency_hz = 32.0\n"),
                {"bad.toml: structure.frequency_hz: 32 is out of range (0, 31.83", "central-difference"});
  CheckContains(ErrorOf("[run]\ndt_s = 0.01\n[structure.ground]\nband_hz = 50\n"),
                {"bad.toml: structure.ground.band_hz: 50 is out of range (0, 50)", "Nyquist"});
  CheckContains(ErrorOf("[structure.desired]\nband_hz = 1000\n"),
                {"structure.desired.band_hz: 1000 is out of range (0, 1000)"});
}

TEST_CASE("enums and presets list the allowed values") {
  CheckContains(ErrorOf("[structure]\nmode = \"hybrid\"\n"),
                {"bad.toml: structure.mode: \"hybrid\" is not allowed", "\"rths\", \"predefined\""});
  CheckContains(ErrorOf("[controller]\nkind = \"pid\"\n"), {"controller.kind", "\"none\", \"ff\""});
  CheckContains(ErrorOf("[plant]\nspecimen = \"spring\"\n"), {"plant.specimen", "\"mr_damper\", \"none\""});
  CheckContains(ErrorOf("[semiactive]\nmode = \"on\"\n"),
                {"semiactive.mode", "\"passive_off\", \"passive_on\", \"constant\""});
  CheckContains(ErrorOf("[structure.ground]\nkind = \"sine\"\n"),
                {"structure.ground.kind", "\"blwn\", \"file\", \"zero\""});
  CheckContains(ErrorOf("[structure]\nderivatives = \"backward\"\n"),
                {"structure.derivatives", "\"extrapolated\", \"central\""});
  CheckContains(ErrorOf("[controller]\nmodel = \"1.0A\"\n"),
                {"bad.toml: controller.model: unknown servo model preset \"1.0A\"", "\"0.0A\", \"2.5A\", \"avg\""});
  CheckContains(ErrorOf("[plant]\nactuator = \"average\"\n"), {"plant.actuator", "\"avg\""});
}

TEST_CASE("kind = \"file\" resolves the path against the scenario's folder") {
  const fs::path dir = TempDir("file");
  fs::create_directories(dir / "records");
  WriteFile(dir / "records/elcentro.txt", "0.0\n0.1\n");
  const std::string scenario = R"(
[structure.ground]
kind = "file"
file = "records/elcentro.txt"
file_dt_s = 0.02
scale = 9810.0
)";
  WriteFile(dir / "quake.toml", scenario);
  const Scenario s = LoadScenario((dir / "quake.toml").string());
  CHECK(fs::equivalent(s.structure.ground.file, dir / "records/elcentro.txt"));
  CHECK(fs::path(s.structure.ground.file).is_absolute());
  CHECK(s.structure.ground.scale == 9810.0);

  WriteFile(dir / "missing.toml", "[structure.ground]\nkind = \"file\"\nfile = \"nowhere.txt\"\n");
  std::string message;
  try {
    LoadScenario((dir / "missing.toml").string());
  } catch (const rths::Error& e) {
    message = e.what();
  }
  CheckContains(message, {"missing.toml: structure.ground.file: file not found", (dir / "nowhere.txt").string()});
  CheckContains(ErrorOf("[structure.desired]\nkind = \"file\"\n"), {"structure.desired.file: missing"});
  fs::remove_all(dir);
}

TEST_CASE("syntax errors name the file, line and column") {
  const std::string message = ErrorOf("[run]\nname = \"x\"\ndt_s = = 0.001\n", "broken.toml");
  CheckContains(message, {"broken.toml:3:", "line 3", "TOML syntax error"});
  CheckContains(ErrorOf("[run]\nname = \"x\"\n[run]\n", "dup.toml"), {"dup.toml:3:"});
}

TEST_CASE("unreadable files are errors naming the path") {
  CHECK_THROWS_WITH_AS(LoadScenario("/nonexistent/rths.toml"), doctest::Contains("/nonexistent/rths.toml"),
                       rths::Error);
}

TEST_CASE("ToToml writes every key: parsing it gives back the same scenario") {
  for (const auto& entry : fs::directory_iterator(kSourceDir / "scenarios")) {
    if (entry.path().extension() != ".toml") continue;
    CAPTURE(entry.path().string());
    auto s = rths::scenario::LoadScenario(entry.path().string());
    // Exercise non-default values of the newer tables too.
    s.controller.kind = rths::control::ControllerKind::kBumplessLp;
    s.controller.model = {1.5e7, 150.0, 250.0, 1.0e5, "custom"};
    s.controller.lqg.q = 12.5;
    s.plant.kind = rths::models::PlantKind::kPhysical;
    s.plant.effects = {};     // the rig mode (scenarios/rig_mode_example.toml) needs kind "linear"
    s.plant.unmodelled = {};
    s.plant.physical.valve_hz = 71.0;
    s.semiactive.mode = rths::control::SemiactiveMode::kPulse;
    s.semiactive.pulse_duty = 0.25;
    const std::string text = rths::scenario::ToToml(s);
    const auto back = rths::scenario::ParseScenario(text, (kSourceDir / "scenarios/x.toml").string());
    CHECK(rths::scenario::ToToml(back) == text);
    CHECK(back.controller.kind == rths::control::ControllerKind::kBumplessLp);
    CHECK(back.controller.model.K == 1.5e7);
    CHECK(back.controller.model.name == "custom");
    CHECK(back.controller.model_low.name == "0.0A");
    CHECK(back.controller.lqg.q == 12.5);
    CHECK(back.plant.kind == rths::models::PlantKind::kPhysical);
    CHECK(back.plant.physical.valve_hz == 71.0);
    CHECK(back.semiactive.pulse_duty == 0.25);
    CHECK(back.run.dt_s == s.run.dt_s);
    CHECK(back.structure.ground.rms == s.structure.ground.rms);
    CHECK(back.steps() == s.steps());
  }
}

TEST_CASE("controller and plant options of Table 1 are validated") {
  CheckContains(ErrorOf("[controller]\nkind = \"poly3\"\ndelay_ms = 20.0\n"),
                {"bad.toml", "controller.delay_ms", "20 is out of range (0, 15]"});
  CheckContains(ErrorOf("[controller]\nkind = \"smith\"\n"),
                {"controller.kind", "\"none\", \"ff\", \"poly3\", \"lead\", \"ff_lp\", \"bumpless_lp\", \"ff_lqg\""});
  CheckContains(ErrorOf("[controller]\nlp_order = 2\n"), {"controller.lp_order", "[3, 8]"});
  CheckContains(ErrorOf("[controller.lqg]\nq = -1.0\n"), {"controller.lqg.q", "(0, 1000000000000]"});
  CheckContains(ErrorOf("[plant.physical]\nvalve_hz = 0.0\n"),
                {"plant.physical.valve_hz", "0 is out of range (0, 10000]"});
  CheckContains(ErrorOf("[plant]\nkind = \"hydraulic\"\n"), {"plant.kind", "\"linear\", \"physical\""});
  CheckContains(ErrorOf("[semiactive]\nmode = \"pulse\"\npulse_duty = 1.0\n"),
                {"semiactive.pulse_duty", "(0, 1)"});
  CheckContains(ErrorOf("[controller]\nmodel = {K = 1.6e7, p = -151.7, b = 250.4, c = 1.061e5}\n"),
                {"controller.model.p", "stable"});
}

TEST_CASE("an empty scenario is an error naming the file: empty, only comments, only table headers") {
  for (const char* text : {"", "\n\n", "# just a comment\n  # another\n", "[run]\n", "[run]\n[structure.ground]\n# none\n",
                           "[plant.effects]\n"}) {
    CAPTURE(text);
    CheckContains(ErrorOf(text, "scenarios/x.toml"), {"scenarios/x.toml: empty scenario: no key is set"});
  }
  // A key anywhere, even deep in a table, makes it a scenario.
  CHECK(ParseScenario("[structure.ground]\nseed = 3\n", "ok.toml").structure.ground.seed == 3);
  // LoadScenario names the file too.
  const fs::path dir = TempDir("empty");
  WriteFile(dir / "empty.toml", "# nothing here\n");
  try {
    LoadScenario((dir / "empty.toml").string());
    FAIL_CHECK("an empty scenario file loaded");
  } catch (const rths::Error& e) {
    CHECK(e.where() == (dir / "empty.toml").string());
    CHECK(std::string(e.problem()).rfind("empty scenario", 0) == 0);
  }
}

TEST_CASE("regression (fuzz_scenario): ToToml escapes control characters, so its text parses back") {
  // Found by fuzz/scenario_fuzz.cpp: a string with an escaped form feed (structure.file is not
  // checked when kind = "sdof") was written raw, and TOML refuses raw control characters.
  const fs::path dir = TempDir("control_chars");
  const std::string path = (dir / "x.toml").string();
  const Scenario s = ParseScenario("[structure]\nfile = \"a\\fb\\u0001c\\u007Fd\\te\\\\f\\\"g\"\n", path);
  CHECK(s.structure.file == (dir / "a\fb\x01" "c\x7F" "d\te\\f\"g").string());
  const std::string text = rths::scenario::ToToml(s);
  CHECK(text.find('\f') == std::string::npos);
  const Scenario back = ParseScenario(text, path);
  CHECK(back.structure.file == s.structure.file);
  CHECK(rths::scenario::ToToml(back) == text);
}

TEST_CASE("regression (fuzz_scenario): ToToml keeps -0.0 a float, so the round trip is exact") {
  // Found by fuzz/scenario_fuzz.cpp: discard_s = -0.0 (allowed: [0, 60]) was written as "-0",
  // which TOML reads as the integer 0, so ToToml of the parsed text differed.
  const Scenario s = ParseScenario("[structure.ground]\ndiscard_s = -0.0\n", "neg_zero.toml");
  REQUIRE(std::signbit(s.structure.ground.discard_s));
  const std::string text = rths::scenario::ToToml(s);
  const Scenario back = ParseScenario(text, "neg_zero.toml");
  CHECK(std::signbit(back.structure.ground.discard_s));
  CHECK(rths::scenario::ToToml(back) == text);
}

namespace {
/// A scenario in which every field differs from its default (and is valid), so that a key missing
/// from the schema (read, write or check) changes the round trip. `rig_mode`: the plant is the
/// linear rig with every effect and unmodelled disturbance on (they need plant.kind = "linear");
/// otherwise the physical rig without them.
Scenario EveryFieldChanged(const fs::path& dir, bool rig_mode) {
  namespace m = rths::models;
  namespace c = rths::control;
  WriteFile(dir / "desired.txt", "0 0\n0.5 1\n1 0\n");
  Scenario s;
  s.run = {"every_field", 0.001, 3.0};
  auto& st = s.structure;
  st.mode = m::StructureMode::kPredefined;
  st.kind = m::StructureKind::kFile;
  st.file = (dir / "not_read_in_predefined_mode.txt").string();
  st.actuator_dof = 3;
  st.mass_kg = 12345.0;
  st.frequency_hz = 3.25;
  st.damping_ratio = 0.045;
  st.specimen_count = 2.5;
  st.derivatives = m::Derivatives::kCentral;
  st.ground = {rths::signal::SignalKind::kZero, 21.0, 1234.5, 5, 1.25, "unused.txt", 0.01, 2.0, 0.3};
  st.desired = {rths::signal::SignalKind::kFile, 7.0, 3.5, 6, 0.75, (dir / "desired.txt").string(), 0.0, -1.5, 0.1};
  auto& ct = s.controller;
  ct.kind = c::ControllerKind::kLead;
  ct.model = {1.5e7, 150.0, 250.0, 1.0e5, "custom"};
  ct.half_step_ahead = true;
  ct.delay_ms = 7.5;
  ct.max_delay_ms = 12.0;
  ct.lead_tp_ms = 0.7;
  ct.lp_cutoff_hz = 200.0;
  ct.lp_order = 4;
  ct.model_low = rths::models::ServoPreset("avg");
  ct.model_high = {1.7e7, 140.0, 300.0, 1.2e5, "custom"};
  ct.current_high_A = 2.0;
  ct.lqg = {11.0, 4.0, 0.8, 0.6, 2.0, 3.0};
  auto& p = s.plant;
  p.kind = rig_mode ? m::PlantKind::kLinear : m::PlantKind::kPhysical;
  p.actuator = rths::models::ServoPreset("2.5A");
  p.physical = {0.03, 21e6, 9e-3, 160.0, 10.0, 71.0, 0.6, 1.1e-2, 330.0, 1.2e9, 3e-11};
  p.specimen = m::Specimen::kNone;
  p.current_dynamics = false;
  p.current_driver = {m::CurrentFilter::kFirstOrder, 150.0, 3.0, 27.0, 70.0, 0.6};
  p.noise_y_mm_rms = 0.01;
  p.noise_f_kN_rms = 0.02;
  p.noise_seed = 9;
  p.ode_rtol = 1e-7;
  auto& d = p.damper;
  for (double* v : {&d.alpha_a, &d.alpha_b, &d.alpha_c, &d.c0_a, &d.c0_b, &d.c0_c, &d.c1_a, &d.c1_b, &d.c1_c,
                    &d.beta_a, &d.beta_b, &d.beta_c, &d.gamma_a, &d.gamma_b, &d.gamma_c, &d.A}) {
    *v *= 1.1;
  }
  d.n = 2.5;
  d.k0 = 0.01;
  d.k1 = 0.02;
  d.x0 = 1.5;
  if (rig_mode) {
    p.effects.pure_delay = m::PureDelay{1.5};
    p.effects.gain_error = m::GainError{1.05};
    p.effects.load_coupling = m::LoadCoupling{0.01};
    p.effects.oil_column_resonance = m::OilColumnResonance{80.0, 0.1};
    p.effects.coulomb_friction = m::CoulombFriction{0.05, 0.8};
    p.effects.backlash = m::Backlash{0.02};
    p.effects.servovalve_saturation = m::ServovalveSaturation{300.0};
    p.effects.sensor_noise = m::SensorNoise{0.003, 0.04};
    p.effects.current_lag = m::CurrentLag{12.0};
    p.effects.damper_scale = m::DamperScale{0.9};
    p.load_coupling_same_sample = false;
    p.unmodelled = {0.01, 30.0, 0.5};
  }
  s.semiactive = {c::SemiactiveMode::kConstant, 1.0, 2.0, 1.0, 0.3, 4, 0.02, 20.0, 150.0};
  s.safety = {false, 100.0, 400.0, 20.0, 0.5, 1.5, 5, 0.7};
  s.lockstep = {50.0, 20.0, 5.0};
  s.realtime = {true, 5, false, 50, false};
  auto& f = s.faults;
  f = {0.01, 0.02, 0.03, 0.04, 10.0, 3, 4096, "plant", rths::lockstep::ProcessFault::kStall, 10, 1.5};
  return s;
}
}  // namespace

TEST_CASE("round trip of a scenario whose every field differs from its default: the structs come back equal") {
  const fs::path dir = TempDir("every_field");
  for (const bool rig_mode : {false, true}) {
    CAPTURE(rig_mode);
    Scenario s = EveryFieldChanged(dir, rig_mode);
    s.path = (dir / "every.toml").string();
    rths::scenario::ReadReferencedFiles(&s);  // as ParseScenario does: the desired record's rows
    rths::scenario::ValidateScenario(s);  // the test's scenario is itself valid
    // Every table differs from its default as a whole.
    const Scenario defaults;
    CHECK(s.run != defaults.run);
    CHECK(s.structure.ground != defaults.structure.ground);
    CHECK(s.structure.desired != defaults.structure.desired);
    CHECK(s.controller.lqg != defaults.controller.lqg);
    CHECK(s.plant.physical != defaults.plant.physical);
    CHECK(s.plant.damper != defaults.plant.damper);
    CHECK(s.semiactive != defaults.semiactive);
    CHECK(s.safety != defaults.safety);
    CHECK(s.lockstep != defaults.lockstep);
    CHECK(s.realtime != defaults.realtime);
    CHECK(s.faults != defaults.faults);

    const std::string text = rths::scenario::ToToml(s);
    Scenario back = ParseScenario(text, s.path);
    back.sha256.clear();
    CHECK(back.run == s.run);
    CHECK(back.structure == s.structure);
    CHECK(back.controller == s.controller);
    CHECK(back.plant.effects == s.plant.effects);
    CHECK(back.plant.unmodelled == s.plant.unmodelled);
    CHECK(back.plant.damper == s.plant.damper);
    CHECK(back.plant == s.plant);
    CHECK(back.semiactive == s.semiactive);
    CHECK(back.safety == s.safety);
    CHECK(back.lockstep == s.lockstep);
    CHECK(back.realtime == s.realtime);
    CHECK(back.faults == s.faults);
    CHECK(back == s);
  }
}

TEST_CASE("a field changed away from its default survives ToToml one at a time (no key silently dropped)") {
  // Each single change must show up in the text ToToml writes and come back from it.
  const fs::path dir = TempDir("one_field");
  Scenario changed = EveryFieldChanged(dir, true);
  rths::scenario::ReadReferencedFiles(&changed);  // as ParseScenario does: the desired record's rows
  const Scenario base;
  const std::string base_text = rths::scenario::ToToml(base);
  std::vector<std::pair<const char*, std::function<void(Scenario&)>>> edits = {
      {"structure", [&](Scenario& s) { s.structure = changed.structure; }},
      {"controller", [&](Scenario& s) { s.controller = changed.controller; }},
      {"plant", [&](Scenario& s) { s.plant = changed.plant; }},
      {"semiactive", [&](Scenario& s) { s.semiactive = changed.semiactive; }},
      {"safety", [&](Scenario& s) { s.safety = changed.safety; }},
      {"lockstep", [&](Scenario& s) { s.lockstep = changed.lockstep; }},
      {"realtime", [&](Scenario& s) { s.realtime = changed.realtime; }},
      {"faults", [&](Scenario& s) { s.faults = changed.faults; }},
  };
  for (auto& [table, edit] : edits) {
    CAPTURE(table);
    Scenario s = base;
    s.run = changed.run;
    edit(s);
    const std::string text = rths::scenario::ToToml(s);
    CHECK(text != base_text);
    Scenario back = ParseScenario(text, (dir / "one.toml").string());
    back.path = s.path;
    back.sha256 = s.sha256;
    CHECK(back == s);
  }
}

TEST_CASE("the loader reads every file the scenario names, once, into the structs; components need no path") {
  const fs::path dir = TempDir("referenced");
  const std::string two = "n 2\nM kg\n1000 0\n0 1000\nK kN/mm\n2 -1\n-1 1\nC kN*s/mm\n0.01 0\n0 0.01\n";
  WriteFile(dir / "two.txt", two);
  WriteFile(dir / "ref.txt", two);
  WriteFile(dir / "ground.txt", "# g\n0.0\n1.0\n-0.5\n");
  WriteFile(dir / "desired.txt", "0 0\n0.5 2\n1 0\n");
  const std::string text = R"(
[structure]
kind = "file"
file = "two.txt"
reference_file = "ref.txt"
actuator_dof = 2
[structure.ground]
kind = "file"
file = "ground.txt"
file_dt_s = 0.01
[structure.desired]
kind = "file"
file = "desired.txt"
)";
  WriteFile(dir / "x.toml", text);
  const Scenario s = LoadScenario((dir / "x.toml").string());
  const rths::models::StructureMatrices m = rths::models::LoadStructureFile((dir / "two.txt").string());
  CHECK(s.structure.matrices == m);
  CHECK(s.structure.reference == m);
  CHECK(s.structure.ground.record.t == std::vector<double>{0.0, 0.01, 0.02});
  CHECK(s.structure.ground.record.value == std::vector<double>{0.0, 1.0, -0.5});
  CHECK(s.structure.desired.record.t == std::vector<double>{0.0, 0.5, 1.0});
  CHECK(s.structure.desired.record.value == std::vector<double>{0.0, 2.0, 0.0});
  // The paths stay (absolute); ToToml writes them, not the data, and reads back the same scenario.
  CHECK(fs::equivalent(s.structure.file, dir / "two.txt"));
  const std::string written = rths::scenario::ToToml(s);
  CHECK(written.find((dir / "two.txt").string()) != std::string::npos);
  Scenario back = ParseScenario(written, (dir / "y.toml").string());
  back.path = s.path;
  back.sha256 = s.sha256;
  CHECK(back == s);
  // The components take the data: with the files gone, the structure and the records still build.
  for (const char* f : {"two.txt", "ref.txt", "ground.txt", "desired.txt"}) fs::remove(dir / f);
  CHECK(rths::models::StructureFromScenario(s.structure).dofs() == 2);
  const std::vector<double> ag = rths::signal::MakeSignal(s.structure.ground, 0.01, 4);
  CHECK(ag == std::vector<double>{0.0, 1.0, -0.5, 0.0});

  // Missing or bad files: the same errors as before, naming the scenario and key, or the file and line.
  CheckContains(ErrorOf(text, (dir / "x.toml").string()),
                {"x.toml: structure.file: file not found", (dir / "two.txt").string()});
  WriteFile(dir / "two.txt", "n 2\nM kg\n1000 0\n");
  WriteFile(dir / "ref.txt", two);
  WriteFile(dir / "ground.txt", "0.0\n1.0\n");
  WriteFile(dir / "desired.txt", "0 0\n1 0\n");
  CheckContains(ErrorOf(text, (dir / "x.toml").string()), {(dir / "two.txt").string() + ":", "file ends inside M"});
  WriteFile(dir / "ref.txt", "n 2\nM kg\n");
  CheckContains(ErrorOf(text, (dir / "x.toml").string()),
                {"x.toml: structure.reference_file: ", (dir / "ref.txt").string(), "file ends inside M"});
  WriteFile(dir / "two.txt", two);
  WriteFile(dir / "ref.txt", "n 1\nM kg\n1\nK kN/mm\n1\nC kN*s/mm\n0\n");
  CheckContains(ErrorOf(text, (dir / "x.toml").string()),
                {"x.toml: structure.reference_file: ref.txt has 1 DOFs but structure.file (two.txt) has 2"});
  WriteFile(dir / "ref.txt", two);
  WriteFile(dir / "ground.txt", "0.0\nabc\n");
  CheckContains(ErrorOf(text, (dir / "x.toml").string()),
                {(dir / "ground.txt").string() + ":2", "'abc' is not a finite number"});
  WriteFile(dir / "ground.txt", "0.0\n1.0\n");
  std::string three = text;
  three.replace(three.find("actuator_dof = 2"), 16, "actuator_dof = 3");
  CheckContains(ErrorOf(three, (dir / "x.toml").string()),
                {"x.toml: structure.actuator_dof", "3 is out of range [1, 2]", (dir / "two.txt").string() + " has 2 DOFs"});
}

TEST_CASE("plant.cvode_rtol: the old name of plant.ode_rtol keeps working; both at once are refused") {
  const Scenario old_name = ParseScenario("[plant]\ncvode_rtol = 1e-7\n", "old.toml");
  CHECK(old_name.plant.ode_rtol == 1e-7);
  const Scenario new_name = ParseScenario("[plant]\node_rtol = 1e-7\n", "new.toml");
  CHECK(new_name.plant.ode_rtol == 1e-7);
  CheckContains(ErrorOf("[plant]\node_rtol = 1e-7\ncvode_rtol = 1e-6\n"),
                {"plant.cvode_rtol: is the old name of plant.ode_rtol; both are given: keep plant.ode_rtol only"});
  // What is written is the new name, and it reads back the same.
  const std::string text = rths::scenario::ToToml(old_name);
  CHECK(text.find("\node_rtol = ") != std::string::npos);
  CHECK(text.find("cvode_rtol") == std::string::npos);
  CHECK(ParseScenario(text, "old.toml").plant.ode_rtol == 1e-7);
}

TEST_CASE("[marths]: the shipped scenarios load their files, round-trip through ToToml, and bad input is refused") {
  for (const char* name : {"none", "rodeac", "ff", "ff_lqg"}) {
    CAPTURE(name);
    const fs::path file = kSourceDir / "scenarios" / "marths" / (std::string("elcentro_") + name + ".toml");
    const Scenario s = LoadScenario(file.string());
    CHECK(s.marths.enabled);
    CHECK(rths::NameOf(rths::control::kMarthsCompensatorNames, s.marths.compensator) == name);
    CHECK(s.marths.files.K_ref.rows() == 29);
    CHECK(s.marths.files.M_ref.cols() == 29);
    CHECK(s.marths.files.rodeac.theta0[0].norm() > 0.0);
    CHECK(s.marths.ground.t.back() == doctest::Approx(41.18));
    CHECK(s.steps() == 42169);
    const std::string text = rths::scenario::ToToml(s);
    CHECK(text.find("[marths]") != std::string::npos);
    const Scenario back = rths::scenario::ParseScenario(text, file.string());
    CHECK(back.marths == s.marths);
    CHECK(rths::scenario::ToToml(back) == text);
  }
  // A scenario without [marths] writes none (its text and hash stay as they were).
  CHECK(rths::scenario::ToToml(ParseScenario("[run]\nname = \"x\"\n", "x.toml")).find("marths") == std::string::npos);
  const std::string base = (kSourceDir / "scenarios" / "marths" / "elcentro_none.toml").string();
  auto refused = [&](const std::string& set, const std::string& key) {
    CAPTURE(set);
    CHECK_THROWS_WITH_AS(LoadScenario(base, {set}), doctest::Contains(key.c_str()), rths::Error);
  };
  refused("marths.compensator=pid", "marths.compensator");
  refused("marths.perturbed_plant=-1", "marths.perturbed_plant");
  refused("marths.force_delay_steps=2", "marths.force_delay_steps");
  refused("marths.ground_scale=0", "marths.ground_scale");
  refused("marths.inverse=asin", "marths.inverse");
  refused("marths.ground_file=nowhere.txt", "marths.ground_file");
  refused("semiactive.mode=clipped_optimal", "semiactive.mode");
  refused("plant.kind=ideal", "plant.kind");
  // A lab's own model of the frame: its DOFs against the matrices and each other.
  refused("marths.interface_dofs=[27, 27, 29]", "named twice");
  refused("marths.story_dofs=[26, 22, 13, 30]", "outside the model's 1..29");
  refused("marths.ground_dofs=[13, 26, 27.5]", "expected an integer");
  refused("marths.interface_dofs=[27, 21]", "marths.interface_dofs");
  // A lab's own coupler: the arms are checked together (models::marths::CouplerProblem).
  auto refused_why = [&](const std::vector<std::string>& sets, const char* why) {
    CAPTURE(sets.front());
    try {
      LoadScenario(base, sets);
      FAIL("accepted");
    } catch (const rths::Error& e) {
      const std::string message = e.what();
      CHECK(message.find("marths.coupler_xv_m") != std::string::npos);
      CHECK(message.find(why) != std::string::npos);
    }
  };
  refused_why({"marths.coupler_alpha_deg=[-30.0, 25.4633]"}, "atan2");
  refused_why({"marths.coupler_yv_m=[-0.127, -0.127]", "marths.coupler_alpha_deg=[-25.4633, -25.4633]"}, "rotation");
  const std::vector<std::string> longer_arm = {"marths.coupler_xv_m=[0.2667, 0.4]",
                                               "marths.coupler_alpha_deg=[-25.4633, 17.614643300007042]"};
  refused_why(longer_arm, "symmetric");  // the as-wired inverse is the symmetric arms' formula
  std::vector<std::string> exact = longer_arm;
  exact.push_back("marths.inverse=exact");
  const Scenario lab = LoadScenario(base, exact);
  CHECK(lab.marths.coupler.xv_m[1] == 0.4);
  CHECK(rths::scenario::ParseScenario(rths::scenario::ToToml(lab), lab.path).marths == lab.marths);
}
