// What every reproduction shares: the output folder rule, the plant check, the batch step of the
// skeleton (studies/study.h).
#include "studies/study.h"

#include <unistd.h>

#include <atomic>
#include <ctime>
#include <string>
#include <filesystem>

#include <fmt/format.h>

#include "core/error.h"
#include "io/output_folder.h"
#include "io/run_signals.h"

namespace rths::studies {

namespace fs = std::filesystem;

std::string ClaimMarkdown(const Claim& c) {
  return fmt::format("- **{}** {}.  \n  {}\n", c.holds ? "Holds:" : "Does not hold:", c.text, c.detail);
}

std::string UtcStamp() {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M UTC", &tm);
  return stamp;
}

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void PrepareOutDir(const fs::path& dir, bool resume) {
  if (!resume) io::RequireNewOrEmptyFolder(dir, "an earlier reproduction (or finish it: --resume)");
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
    } else if (io::ReadRunSignals(results[0].dir).At("y_mm").values ==
               io::ReadRunSignals(results[1].dir).At("y_mm").values) {
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

std::vector<RunResult> RunStudyBatch(std::vector<RunSpec>* specs, const ReproduceOptions& opts,
                                     const std::string& intro, const Progress& on_run) {
  Preflight(specs, opts.overrides, opts.log);
  if (opts.log) opts.log(intro);
  if (opts.run_batch) return opts.run_batch(*specs, on_run);
  return RunBatch(*specs, opts.jobs, opts.progress, on_run, "rths reproduce", opts.batch);
}

std::string StoppedText(const RunResult& r) {
  if (r.ok) return "no";
  std::string s = r.error;
  // "integrator exited with code 6: <the monitor's reason>" -> the reason
  if (const auto p = s.find("exited with code"); p != std::string::npos) {
    if (const auto c = s.find(": ", p); c != std::string::npos) s = s.substr(c + 2);
  }
  for (char& ch : s) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  return s.empty() ? "stopped" : s;
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

}  // namespace rths::studies
