/// @file Checks across keys and against files (after the per-key ranges): ValidateScenario.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "control/ambc.h"
#include "control/ats.h"
#include "control/lti_controller.h"
#include "core/names.h"
#include "lockstep/step_table.h"
#include "scenario/walk.h"

namespace rths::scenario {
namespace detail {

std::filesystem::path ResolveFile(const std::string& scenario_path, const std::string& file) {
  std::filesystem::path p(file);
  if (p.is_relative()) p = std::filesystem::path(scenario_path).parent_path() / p;
  return std::filesystem::absolute(p).lexically_normal();
}

namespace {

void CheckFileExists(const Check& check, const std::string& key, const std::string& scenario_path,
                     const std::string& file) {
  const std::filesystem::path resolved = ResolveFile(scenario_path, file);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(resolved, ec)) {
    check.Fail(key, fmt::format("file not found: {} (paths are relative to the scenario file's folder)",
                                resolved.string()));
  }
}

void ValidateRun(const RunConfig& r, const Check& check) {
  if (r.name.empty() || !std::all_of(r.name.begin(), r.name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
               c == '-' || c == '.';
      })) {
    check.Fail("run.name", fmt::format("\"{}\" is not a usable name (allowed: non-empty, letters, digits, "
                                       "'_', '-', '.')",
                                       r.name));
  }
  if (r.duration_s < r.dt_s) {
    check.Fail("run.duration_s", fmt::format("{} is shorter than one step (run.dt_s = {})", r.duration_s, r.dt_s));
  }
}

void ValidateSignal(const signal::SignalSpec& s, std::string_view prefix, const std::string& scenario_path,
                    const Check& check) {
  auto key = [&](std::string_view k) { return fmt::format("{}.{}", prefix, k); };
  if (!std::isfinite(s.scale) || s.scale == 0.0) {
    check.Fail(key("scale"), fmt::format("{} is not allowed (allowed: any finite value other than 0)", s.scale));
  }
  if (s.kind == signal::SignalKind::kFile) {
    if (s.file.empty()) check.Fail(key("file"), "missing: kind = \"file\" needs a file path");
    CheckFileExists(check, key("file"), scenario_path, s.file);
  }
}

/// The controller's design checks that span keys (an `lti` transfer function's coefficients and
/// poles; the bounds, initial values and windows of `ats` and `ambc`): the design is made once
/// here, as the participant will make it, and its error is given the scenario's file name.
void ValidateController(const control::ControllerConfig& c, double dt_s, const Check& check) {
  try {
    if (c.kind == control::ControllerKind::kLti) control::MakeLtiDesign(c.lti, dt_s);
    if (c.kind == control::ControllerKind::kAts) control::MakeAtsDesign(c.ats, dt_s);
    if (c.kind == control::ControllerKind::kAmbc) control::MakeAmbcDesign(c.ambc, c.model, dt_s);
  } catch (const Error& e) {
    check.Fail(e.where(), e.problem());
  }
}

/// structure.reference_file (the benchmark criteria's monolithic reference, participants/benchmark_run.h):
/// only beside a structure file, and present (ReadReferencedFiles reads it and compares its DOFs).
void ValidateReferenceFile(const models::StructureConfig& st, const std::string& scenario_path, const Check& check) {
  const char* key = "structure.reference_file";
  if (st.mode != models::StructureMode::kRths || st.kind != models::StructureKind::kFile) {
    check.Fail(key, fmt::format("needs structure.mode = \"rths\" and structure.kind = \"file\" (got \"{}\", \"{}\"): "
                                "the reference is compared with a structure file's floors; leave it \"\" otherwise",
                                NameOf(models::kStructureModeNames, st.mode), NameOf(models::kStructureKindNames, st.kind)));
  }
  CheckFileExists(check, key, scenario_path, st.reference_file);
}

void ValidateStructure(const models::StructureConfig& st, const std::string& scenario_path, const Check& check) {
  if (st.mode == models::StructureMode::kRths && st.kind == models::StructureKind::kFile) {
    if (!st.subtract_specimen) {
      if (st.file.empty()) check.Fail("structure.file", "missing: kind = \"file\" needs a structure file");
      CheckFileExists(check, "structure.file", scenario_path, st.file);
    } else if (st.reference_file.empty()) {
      check.Fail("structure.subtract_specimen", "needs structure.reference_file, the structure to subtract from");
    }
    check.InRange("structure.actuator_dof", st.actuator_dof,
                  {1, 10000, false, false, "1-based; at most the structure's number of DOFs"});
  } else if (st.mode == models::StructureMode::kRths && st.actuator_dof != 1) {
    check.Fail("structure.actuator_dof", fmt::format("{}: an SDOF structure has one DOF (only kind = \"file\" takes "
                                                     "another)",
                                                     st.actuator_dof));
  }
  if (!st.reference_file.empty()) ValidateReferenceFile(st, scenario_path, check);
  try {
    st.integrator.Validate();
  } catch (const Error& e) {  // "alpha" is structure.alpha_os_alpha in the file
    check.Fail(e.where() == "alpha" ? "structure.alpha_os_alpha" : "structure." + e.where(), e.problem());
  }
  if (st.mode == models::StructureMode::kRths && st.kind == models::StructureKind::kSdof) {
    try {
      st.spring.Validate();
    } catch (const Error& e) {
      check.Fail("structure.spring." + e.where(), e.problem());
    }
  }
  if (st.integrator.kind == models::IntegratorKind::kRk4UnitDelay && st.Nonlinear())
    check.Fail("structure.integrator", "rk4_unit_delay runs linear structures only (the benchmark's reference-code "
                                       "loop): choose central_difference, cr, alpha_os or newmark_implicit");
  ValidateSignal(st.ground, "structure.ground", scenario_path, check);
  ValidateSignal(st.desired, "structure.desired", scenario_path, check);
}

void ValidatePlant(const models::PlantConfig& p, const Check& check) {
  try {
    p.damper.Validate();
  } catch (const Error& e) {
    // "MrDamperParams: alpha_a" -> plant.damper.alpha_a
    const std::string& w = e.where();
    const std::size_t colon = w.rfind(": ");
    check.Fail(fmt::format("plant.damper.{}", colon == std::string::npos ? w : w.substr(colon + 2)), e.problem());
  }
  // The benchmark plant's stability (its keys' ranges are checked already): every kind, like
  // plant.damper, so a table that cannot run is refused even while another kind is chosen.
  models::ValidateBenchmarkParams(p.benchmark.params, fmt::format("{}: plant.benchmark", check.file()));
  models::ValidateBenchmarkDaq(p.benchmark.daq, fmt::format("{}: plant.benchmark.daq", check.file()));
  if (p.current_driver.kind == models::CurrentFilter::kEq40 &&
      p.current_driver.lag_zero_rad_s == p.current_driver.lag_pole_rad_s)
    check.Fail("plant.current_driver.lag_zero_rad_s",
               fmt::format("{} equals lag_pole_rad_s: Eq. 40 needs a zero apart from its pole",
                           p.current_driver.lag_zero_rad_s));
  if (p.RigMode() && p.kind != models::PlantKind::kLinear) {
    check.Fail(p.effects.Empty() ? "plant.unmodelled" : "plant.effects",
               fmt::format("rig mode needs plant.kind = \"linear\" (got \"{}\"): the effects act around the "
                           "linear actuator model",
                           NameOf(models::kPlantKindNames, p.kind)));
  }
}

void ValidateFaults(const lockstep::FaultConfig& f, const Check& check) {
  if (const double sum = f.drop + f.duplicate + f.delay + f.reorder; !(sum <= 0.5 + 1e-12)) {
    check.Fail("faults", fmt::format("drop + duplicate + delay + reorder = {} + {} + {} + {} = {:.6g}: the sum must not "
                                     "exceed 0.5 (each in [0, 0.5])",
                                     f.drop, f.duplicate, f.delay, f.reorder, sum));
  }
  if (f.recv_buf_bytes != 0) {
    check.InRange("faults.recv_buf_bytes", static_cast<double>(f.recv_buf_bytes),
                  {1024.0, 134217728.0, false, false, "0 for the host's default, else [1024, 2^27]"});
  }
  if (f.process_role.empty() && f.process_kind == lockstep::ProcessFault::kNone) return;
  check.OneOf("faults.process.role", f.process_role, {lockstep::kRoster.begin(), lockstep::kRoster.end()});
  if (f.process_kind == lockstep::ProcessFault::kNone) {
    check.Fail("faults.process.kind", fmt::format("missing (allowed: {})", QuotedNames(lockstep::kProcessFaultNames)));
  }
}

/// [marths]: its files given and present, and nothing set that its loop would not run.
void ValidateMarths(const Scenario& s, const Check& check) {
  const control::MarthsConfig& m = s.marths;
  if (!m.enabled) return;
  for (const auto& [key, file] : {std::pair{"marths.reference_k_file", &m.reference_k_file},
                                  {"marths.reference_m_file", &m.reference_m_file},
                                  {"marths.rodeac_file", &m.rodeac_file},
                                  {"marths.ground_file", &m.ground_file}}) {
    if (file->empty()) {
      check.Fail(key, "is required with marths.enabled (the benchmark's files: data/marths/, docs/marths.md)");
    } else {
      CheckFileExists(check, key, s.path, *file);
    }
  }
  if (s.semiactive.mode == control::SemiactiveMode::kClippedOptimal) {
    check.Fail("semiactive.mode", "\"clipped_optimal\" controls the one-actuator structure; the maRTHS loop "
                                  "(marths.enabled) has no damper");
  }
  if (s.plant.kind == models::PlantKind::kIdeal) {
    check.Fail("plant.kind", "\"ideal\" answers desired_t k, but the maRTHS loop's integrator answers "
                             "desired_t k from measured_t k (a cycle); leave plant.kind at its default "
                             "(marths.enabled runs the benchmark's own plant)");
  }
  if (const std::string why = models::marths::CouplerProblem(m.coupler, m.inverse); !why.empty()) {
    check.Fail("marths.coupler_xv_m", fmt::format("(with coupler_yv_m, coupler_alpha_deg, inverse): {}", why));
  }
}

}  // namespace
}  // namespace detail

void ValidateScenario(const Scenario& s) {
  using namespace detail;
  const Check check(DisplayName(s.path));
  // run.dt_s and run.duration_s first: every other range and check depends on them.
  CheckRunRanges(check, s);
  ValidateRun(s.run, check);
  CheckRanges(check, s);
  ValidateStructure(s.structure, s.path, check);
  if (s.semiactive.mode == control::SemiactiveMode::kClippedOptimal &&
      s.structure.mode != models::StructureMode::kRths) {
    check.Fail("semiactive.mode", "\"clipped_optimal\" needs a structure to control (structure.mode = \"rths\")");
  }
  ValidateController(s.controller, s.run.dt_s, check);
  ValidatePlant(s.plant, check);
  if (s.structure.subtract_specimen &&
      (s.plant.kind != models::PlantKind::kBenchmark || s.structure.kind != models::StructureKind::kFile)) {
    check.Fail("structure.subtract_specimen", "true needs structure.kind = \"file\" and plant.kind = \"benchmark\" "
                                              "(the specimen is [plant.benchmark]'s)");
  }
  ValidateFaults(s.faults, check);
  ValidateMarths(s, check);
}

}  // namespace rths::scenario
