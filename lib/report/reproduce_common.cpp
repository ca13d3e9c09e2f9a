// What every reproduction shares: the output folder rule and the plant check.
#include <unistd.h>

#include <atomic>
#include <ctime>
#include <string>
#include <filesystem>

#include <fmt/format.h>

#include "core/error.h"
#include "io/output_folder.h"
#include "report/reproduce.h"

namespace rths::report {

namespace fs = std::filesystem;

std::string UtcStamp() {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M UTC", &tm);
  return stamp;
}

void PrepareOutDir(const fs::path& dir) {
  io::RequireNewOrEmptyFolder(dir, "an earlier reproduction");
  fs::create_directories(dir);
}

void RequirePlant(const std::string& plant, const fs::path& scratch_parent) {
  if (plant == "linear") return;
  if (plant != "physical") {
    throw Error("--plant", fmt::format("unknown plant '{}' (allowed: physical, linear)", plant));
  }
  // The probe: 0.1 s of 0-50 Hz noise at 2.5 A, no controller, on both plants. The physics-based
  // actuator must run, and must not give the linear model's numbers bit for bit.
  static std::atomic<int> counter{0};
  const fs::path scratch = scratch_parent / fmt::format(".plant-probe-{}-{}", ::getpid(), counter++);
  fs::remove_all(scratch);
  std::vector<RunSpec> specs;
  for (const char* kind : {"physical", "linear"}) {
    scenario::Scenario s;
    s.run.name = fmt::format("probe-{}", kind);
    s.run.duration_s = 0.1;
    s.structure.mode = models::StructureMode::kPredefined;
    s.structure.desired.kind = signal::SignalKind::kBlwn;
    s.structure.desired.band_hz = 50.0;
    s.structure.desired.rms = 0.254;
    s.structure.desired.taper_s = 0.02;
    s.controller.kind = control::ControllerKind::kNone;
    s.plant.kind = ParseName(models::kPlantKindNames, kind, "--plant");
    s.plant.actuator = models::ServoPreset("2.5A");
    s.plant.specimen = models::Specimen::kMrDamper;
    s.semiactive.mode = control::SemiactiveMode::kPassiveOn;
    specs.push_back({fmt::format("plant probe ({})", kind), s, scratch / kind});
  }
  std::string problem;
  try {
    Preflight(specs);
    const auto results = RunBatch(specs, 1);
    if (!results[0].ok) {
      problem = "the physics-based actuator failed in a 0.1 s probe: " + results[0].error;
    } else if (!results[1].ok) {
      problem = "the linear plant failed in a 0.1 s probe: " + results[1].error;
    } else if (ReadTrace(results[0].dir).y_mm == ReadTrace(results[1].dir).y_mm) {
      problem = "this build's plant ignores plant.kind = \"physical\" (it gave the linear model's "
                "numbers bit for bit): the physics-based actuator of docs/models.md section 5 is not "
                "available yet";
    }
  } catch (const Error& e) {
    problem = fmt::format("the physics-based actuator is not available in this build: {}", e.problem());
  }
  std::error_code ec;
  fs::remove_all(scratch, ec);
  if (!problem.empty()) {
    throw Error("--plant physical", problem + ". Run with --plant linear (the three-pole models of "
                                              "Eqs. 28-30) until it is.");
  }
}

control::ControllerConfig ControllerKind(const std::string& kind) {
  control::ControllerConfig c;
  c.kind = ParseName(control::kControllerKindNames, kind, "controller.kind");
  return c;
}

control::ControllerConfig ControllerDelay(const std::string& kind, double delay_ms) {
  auto c = ControllerKind(kind);
  c.delay_ms = delay_ms;
  return c;
}

control::ControllerConfig ControllerModel(const std::string& kind, const std::string& preset) {
  auto c = ControllerKind(kind);
  c.model = models::ServoPreset(preset);
  return c;
}

}  // namespace rths::report
