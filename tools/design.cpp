// rths-design: design the controller a scenario names and print its summary (docs/controllers.md).
//   rths design SCENARIO.toml [--out FILE.json]
// Prints the coefficients, filter sections, LQR and Kalman gains, transfer functions and poles (lti),
// closed-loop poles, margins and G_yr on the design model and on the 0.0 A / avg / 2.5 A models (or,
// for a scenario with plant.kind = "benchmark", on its plant Gp); --out writes the same as JSON.
// Exit codes: 0 ok, 2 bad command line, scenario or design.
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "control/design.h"
#include "ident/design_model.h"
#include "control/lti.h"
#include "models/benchmark_plant.h"
#include "scenario/scenario.h"
#include "cli.h"
#include "set_hint.h"

int main(int argc, char** argv) {
  CLI::App app{"rths design: design the controller a scenario names, from its models, and analyse it"};
  std::string scenario_path, out;
  app.add_option("scenario", scenario_path, "scenario file (TOML)")->required();
  app.add_option("--out", out, "also write the summary as JSON to this file");
  std::vector<std::string> sets;
  rths::tools::AddSetOption(app, &sets);
  rths::tools::NameCommand(app, "design");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) {
    if (code == rths::kExitUsage) rths::tools::PrintSetHints(app, argc, argv, "design");
    return code;
  }
  try {
    rths::scenario::Scenario s = rths::scenario::LoadScenario(scenario_path, sets);
    const std::string design_note = rths::ident::ResolveDesignModel(&s);  // the plant's own model
    std::vector<rths::control::DesignPlant> plants;
    if (s.plant.kind == rths::models::PlantKind::kBenchmark) {
      // Gp is m/m, i.e. mm/mm: its ZOH model is the plant u -> y as the controller sees it.
      const auto g = rths::models::BenchmarkPlant::Make(s.plant.benchmark.params, s.run.dt_s);
      plants.push_back({"benchmark plant Gp ([plant.benchmark])", {g.Phi, g.Gamma, g.C, 0.0, s.run.dt_s}});
    } else if (s.plant.kind == rths::models::PlantKind::kLinear && s.plant.actuator.name == "custom") {
      // A plant of the user's own (an identified model file): the design is judged on it, at the
      // scenario's step, not on the paper's three.
      plants.push_back({"the scenario's [plant] actuator (custom, ZOH)",
                        rths::control::ServoZoh(s.plant.actuator, s.run.dt_s)});
    }
    std::printf("rths design: %s, dt = %g s%s\n", scenario_path.c_str(), s.run.dt_s,
                s.run.dt_s == rths::scenario::RunConfig{}.dt_s ? " (the default: the file sets no [run] dt_s)" : "");
    if (!design_note.empty()) std::printf("%s\n", design_note.c_str());
    const rths::control::DesignSummary d = rths::control::DesignController(s.controller, s.run.dt_s, plants);
    std::fputs(d.Report().c_str(), stdout);
    if (!out.empty()) {
      std::ofstream f(out);
      f << d.ToJson().dump(2) << "\n";
      if (!f) throw std::runtime_error("cannot write " + out);
      std::printf("wrote %s\n", out.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths design: %s\n", e.what());
    return rths::kExitUsage;
  }
}
