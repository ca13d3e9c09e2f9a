// The diagnosed model as a scenario (diagnosis/model_file.h) and the terminal summary's handling
// of fits pinned at a search bound; end to end: rig-mode runs -> records -> rths diagnose ->
// fitted_model.toml -> rths run and rths design take it.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <doctest/doctest.h>

#include "diagnosis/channel_models.h"
#include "diagnosis/diagnosis.h"
#include "diagnosis/model_file.h"
#include "scenario/scenario.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using rths::diagnosis::EffectResult;
using rths::diagnosis::Result;

int RunTool(const std::string& tool, const std::string& args, std::string* output) {
  const fs::path txt = fs::temp_directory_path() / ("rths_dmf_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = std::string(RTHS_BIN_DIR) + "/rths-" + tool + " " + args + " > " + txt.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(txt);
  std::stringstream ss;
  ss << in.rdbuf();
  *output = ss.str();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

EffectResult Effect(const std::string& name, const std::string& channel, std::map<std::string, double> params,
                    bool selected, bool at_bound = false) {
  EffectResult e;
  e.name = name;
  e.channel = channel;
  e.params = std::move(params);
  e.selected = selected;
  e.at_bound = at_bound;
  return e;
}

Result MadeUpResult() {
  Result r;
  r.dt_s = 0.0005;
  r.train = {"a.csv"};
  r.test = {"b.csv"};
  r.verdict = {"pure_delay", "damper_scale"};
  r.effects = {Effect("pure_delay", "y", {{"tau_ms", 2.1}}, true), Effect("damper_scale", "f", {{"scale", 1.14}}, true),
               Effect("oil_column_resonance", "y", {{"f_hz", 899.0}, {"zeta", 0.05}}, false, true),
               Effect("backlash", "y", {{"gap_mm", 0.01}}, false)};
  return r;
}

}  // namespace

TEST_CASE("FittedScenario: the nominal model with the selected effects, as a runnable scenario") {
  rths::diagnosis::NominalModel m = rths::diagnosis::PaperModel();
  m.actuator.K *= 1.1;
  m.damper.c0_a *= 0.9;
  const Result r = MadeUpResult();
  const auto s = rths::diagnosis::FittedScenario(m, r);
  CHECK(s.plant.kind == rths::models::PlantKind::kLinear);
  CHECK(s.plant.actuator.K == m.actuator.K);
  CHECK(s.controller.model.K == m.actuator.K);
  CHECK(s.plant.damper.c0_a == m.damper.c0_a);
  REQUIRE(s.plant.effects.pure_delay.has_value());
  CHECK(s.plant.effects.pure_delay->tau_ms == 2.1);
  REQUIRE(s.plant.effects.damper_scale.has_value());
  CHECK(s.plant.effects.damper_scale->scale == 1.14);
  CHECK_FALSE(s.plant.effects.oil_column_resonance.has_value());  // not selected
  CHECK_FALSE(s.plant.effects.backlash.has_value());

  // The text loads back as the same plant, and diagnose --model reads its nominal part.
  const fs::path dir = rths_test::TempDir("model_file");
  const fs::path file = dir / "fitted_model.toml";
  std::ofstream(file) << rths::diagnosis::FittedModelToml(m, r);
  const auto back = rths::scenario::LoadScenario(file.string());
  CHECK(back.plant.damper == s.plant.damper);
  CHECK(back.plant.effects == s.plant.effects);
  CHECK(back.plant.current_driver == s.plant.current_driver);
  CHECK(back.plant.actuator.K == s.plant.actuator.K);  // (its name reads back as "custom")
  CHECK(back.plant.actuator.c == s.plant.actuator.c);
  const auto nominal = rths::diagnosis::LoadModel(file.string());
  CHECK(nominal.actuator.K == m.actuator.K);
  CHECK(nominal.damper.c0_a == m.damper.c0_a);
  CHECK(nominal.has_damper);
}

TEST_CASE("Summary leaves out fits pinned at a search bound, and says so") {
  const std::string s = rths::diagnosis::Summary(MadeUpResult());
  CHECK(s.find("backlash") != std::string::npos);
  const auto listed = s.find("  " + std::string("  oil_column_resonance"));
  CHECK(listed == std::string::npos);
  CHECK(s.find("not shown: oil_column_resonance") != std::string::npos);
}

TEST_CASE("rths diagnose writes fitted_model.toml; rths run and rths design take it") {
  const fs::path dir = rths_test::TempDir("model_file_cli");
  const std::string scenario = std::string(RTHS_SOURCE_DIR) + "/scenarios/rig_mode_example.toml";
  std::string out;
  for (const auto& [name, seed] : {std::pair{"train", 3}, std::pair{"test", 11}}) {
    const fs::path run = dir / name;
    REQUIRE_MESSAGE(RunTool("run", scenario + " --transport memq --skip-space-check --compact --set run.duration_s=12 "
                                        "--set structure.desired.seed=" + std::to_string(seed) + " --out " + run.string(),
                            &out) == 0,
                    out);
    REQUIRE_MESSAGE(RunTool("record", run.string(), &out) == 0, out);
  }
  const int code = RunTool("diagnose", "--train " + (dir / "train" / "record.csv").string() + " --test " +
                                           (dir / "test" / "record.csv").string() + " --out " + (dir / "diag").string(),
                           &out);
  INFO(out);
  REQUIRE(code == 0);
  CHECK(out.find("fitted model: ") != std::string::npos);
  const fs::path model = dir / "diag" / "fitted_model.toml";
  const auto s = rths::scenario::LoadScenario(model.string());
  // The example switches on a 2 ms delay and a 15 % stronger damper; the diagnosis finds both.
  REQUIRE(s.plant.effects.pure_delay.has_value());
  CHECK(s.plant.effects.pure_delay->tau_ms == doctest::Approx(2.0).epsilon(0.1));
  REQUIRE(s.plant.effects.damper_scale.has_value());
  CHECK(s.plant.effects.damper_scale->scale == doctest::Approx(1.15).epsilon(0.03));
  CHECK(RunTool("design", model.string(), &out) == 0);
  CHECK_MESSAGE(RunTool("run", model.string() + " --transport memq --skip-space-check --compact --set run.duration_s=0.5 --out " +
                                   (dir / "rehearse").string(),
                        &out) == 0,
                out);
}
