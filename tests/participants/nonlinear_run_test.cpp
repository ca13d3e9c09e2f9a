// Yielding numerical substructures through the lockstep (issue 44): the shipped reference SDOF
// (scenarios/nonlinear/reference_sdof.toml) with every integrator gives the CVODE reference's peak,
// residual and hysteretic energy in summary.json; a yielding run is bit-identical on memq and udpm;
// [structure.spring] and structure.integrator are validated with the key named.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/run_log.h"
#include "models/integrator_accuracy.h"
#include "models/structure_file.h"
#include "models/structure_reference.h"
#include "scenario/scenario.h"
#include "signal/history.h"
#include "run_support.h"
#include "udpm_support.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

const std::string kReference = std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear/reference_sdof.toml";

nlohmann::json Summary(const fs::path& dir) { return nlohmann::json::parse(std::ifstream(dir / "summary.json")); }

/// The error thrown loading `kReference` with `sets`, or "" if it loads.
std::string LoadError(const std::vector<std::string>& sets) {
  try {
    rths::scenario::LoadScenario(kReference, sets);
  } catch (const rths::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("reference_sdof as shipped: every integrator through the lockstep gives the CVODE reference's response") {
  const auto s = rths::scenario::LoadScenario(kReference);
  REQUIRE(s.structure.Nonlinear());
  // The reference, independently of the integrators: the continuous model by CVODE's BDF.
  const auto n = static_cast<std::size_t>(s.steps());
  const auto ground = rths::signal::MakeSignal(s.structure.ground, s.run.dt_s, n);
  const auto ref = rths::models::SolveReference(rths::models::NonlinearFromScenario(s.structure), s.run.dt_s, ground);
  const auto summary = rths::models::Summarize(ref.x_mm);
  MESSAGE(fmt::format("reference ({}): peak {:.4f} mm, residual {:.4f} mm, E_h {:.2f} kN mm", ref.method,
                      summary.peak_roof_mm, summary.residual_roof_mm, ref.hysteretic_energy_kN_mm));
  CHECK(summary.peak_roof_mm / 4.0 > 1.5);  // it yields: ductility about 2
  for (const char* integrator : {"central_difference", "cr", "alpha_os", "newmark_implicit"}) {
    CAPTURE(integrator);
    const fs::path dir = rths_test::TempDir(std::string("nonlinear_ref_") + integrator);
    std::string output;
    REQUIRE(rths_test::RunCli(kReference + " --transport memq --compact --set structure.integrator=" + integrator +
                                  " --out " + (dir / "run").string(),
                              &output) == 0);
    CAPTURE(output);
    const auto j = Summary(dir / "run");
    REQUIRE(j.contains("structure_peak_displacement_mm"));
    const double peak = j["structure_peak_displacement_mm"].get<double>();
    const double residual = j["structure_residual_displacement_mm"].get<double>();
    const double energy = j["structure_hysteretic_energy_kN_mm"].get<double>();
    MESSAGE(fmt::format("{}: peak {:.4f} mm, residual {:.4f} mm, E_h {:.2f} kN mm", integrator, peak, residual, energy));
    CHECK(std::abs(peak / summary.peak_roof_mm - 1.0) < 0.01);
    CHECK(std::abs(energy / ref.hysteretic_energy_kN_mm - 1.0) < 0.01);
    CHECK(std::abs(residual - summary.residual_roof_mm) < 0.01 * summary.peak_roof_mm);
    CHECK(j["structure_ductility"].get<double>() == doctest::Approx(peak / 4.0));
    CHECK(output.find("  structure          floor 1: peak ") != std::string::npos);
    CHECK(j["structure_peak_drift_mm"].get<double>() == peak);  // an SDOF: its drift is its displacement
  }
}

TEST_CASE("the 9-story building with Bouc-Wen stories, semiactive, as shipped: it yields; linear stories are today's run") {
  const std::string shipped = std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear/ohtori9_semiactive.toml";
  const fs::path dir = rths_test::TempDir("nonlinear_ohtori9");
  std::string output;
  REQUIRE(rths_test::RunCli(shipped + " --transport memq --compact --out " + (dir / "run").string(), &output) == 0);
  CAPTURE(output);
  const auto j = Summary(dir / "run");
  CHECK(j["structure_floor"] == 9);
  CHECK(j["structure_peak_drift_story"] == 1);  // the dampers' story, the softest (65 kN/mm)
  CHECK(j["structure_ductility"].get<double>() > 1.5);  // it yields (2.3 measured, the scenario's comment)
  CHECK(j["structure_hysteretic_energy_kN_mm"].get<double>() > 0.0);
  // The same building with linear stories (a shear-building file) runs today's path: its log is the
  // matrix file's (data/buildings/ohtori9_ns.txt) bit for bit.
  std::string text = "n 9\nfloors kg\n505000 494500 494500 494500 494500 494500 494500 494500 535000\n";
  for (const char* k : {"65.0", "295.6", "355.9", "191.9", "193.3", "141.9", "157.9", "80.2", "194.4"})
    text += std::string("story linear k_kN_per_mm=") + k + "\n";
  std::ofstream(dir / "linear9.txt") << text << "damping modal 0.02\n";
  const auto matrix = rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/fig11_base.toml",
                                                   {"run.duration_s=2"});
  auto shear = rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/fig11_base.toml",
                                            {"run.duration_s=2", "structure.file=" + (dir / "linear9.txt").string()});
  CHECK_FALSE(shear.structure.Stepped());
  fs::create_directories(dir / "matrix");
  fs::create_directories(dir / "shear");
  REQUIRE(rths_test::RunMemq({matrix}, dir / "matrix").code == 0);
  REQUIRE(rths_test::RunMemq({shear}, dir / "shear").code == 0);
  CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((dir / "shear" / "log.lcm").string())) ==
        rths::io::PayloadDigest(rths::io::ReadRunLog((dir / "matrix" / "log.lcm").string())));
}

TEST_CASE("every scenario in scenarios/nonlinear runs as shipped, and its structure yields") {
  int n = 0;
  for (const auto& e : fs::directory_iterator(std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear")) {
    if (e.path().extension() != ".toml") continue;
    CAPTURE(e.path().string());
    ++n;
    const fs::path dir = rths_test::TempDir("shipped_" + e.path().stem().string());
    std::string output;
    CHECK(rths_test::RunCli(e.path().string() + " --transport memq --compact --out " + (dir / "run").string(), &output) ==
          0);
    CAPTURE(output);
    const auto j = Summary(dir / "run");
    CHECK(j["status"] == "completed");
    CHECK(j["structure_ductility"].get<double>() > 1.5);
  }
  CHECK(n >= 3);
}

TEST_CASE("every integrator within 1 % of the reference's peak drift on the shipped cases, converging at dt/2, dt/4") {
  // The damper's force as the run measured it (log), fed open-loop to each integrator and to the
  // CVODE reference (the force linear between samples), so that the difference is the integrator's
  // own; at dt/2 and dt/4 the same continuous ground and force (linear between the run's samples).
  // Prints the table of docs/structures.md ("Each integrator on the shipped cases").
  for (const char* name : {"sdof_damper", "benchmark_damper", "ohtori9_semiactive"}) {
    CAPTURE(name);
    const std::string file = std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear/" + name + ".toml";
    const auto s = rths::scenario::LoadScenario(file);
    const fs::path dir = rths_test::TempDir(std::string("accuracy_") + name);
    REQUIRE(rths_test::RunMemq({s}, dir).code == 0);
    const auto log = rths::io::ReadRunLog((dir / "log.lcm").string());
    const auto n = static_cast<std::size_t>(log.CompleteSteps());
    std::vector<double> force(n);
    for (std::size_t k = 0; k < n; ++k) force[k] = log.measured[k].f_kN;
    const double dt = s.run.dt_s;
    const auto ratio = [dt](double h) { return static_cast<int>(std::lround(dt / h)); };
    const auto ground = [&](double h) {
      return rths::signal::MakeSignal(s.structure.ground, h, n * static_cast<std::size_t>(ratio(h)));
    };
    const auto measured = [&](double h) { return rths::models::ResampleLinear(force, ratio(h)); };
    std::vector<rths::models::IntegratorConfig> configs;
    for (const auto kind : {rths::models::IntegratorKind::kCentralDifference, rths::models::IntegratorKind::kCr,
                            rths::models::IntegratorKind::kAlphaOs, rths::models::IntegratorKind::kNewmarkImplicit}) {
      rths::models::IntegratorConfig c;
      c.kind = kind;
      configs.push_back(c);
    }
    const auto building = rths::models::NonlinearFromScenario(s.structure);
    const auto study = rths::models::MeasureAccuracy(building, dt, ground, 3, configs, measured, 1e-10);
    const auto peak_of = [](const rths::models::ResponseSummary& r) {
      return *std::max_element(r.peak_drift_mm.begin(), r.peak_drift_mm.end());
    };
    const auto residual_of = [](const rths::models::ResponseSummary& r) {
      return *std::max_element(r.residual_drift_mm.begin(), r.residual_drift_mm.end(),
                               [](double a, double b) { return std::abs(a) < std::abs(b); });
    };
    const double ref_peak = peak_of(study.reference_summary);
    MESSAGE(fmt::format("| {} | reference (CVODE) | {} | {:.4f} | | {:.4f} | {:.1f} | | |", name, dt, ref_peak,
                        residual_of(study.reference_summary), study.reference.hysteretic_energy_kN_mm));
    for (std::size_t i = 0; i < study.rows.size(); ++i) {
      const auto& row = study.rows[i];
      const double peak = peak_of(row.summary);
      MESSAGE(fmt::format("| | {} | {} | {:.4f} | {:+.3f} % | {:.4f} | {:.1f} | {:.4f} % | {} |", row.integrator,
                          row.dt_s, peak, 100.0 * (peak / ref_peak - 1.0), residual_of(row.summary),
                          row.hysteretic_energy_kN_mm, row.nrmse_pct,
                          row.order == 0.0 ? std::string() : fmt::format("{:.2f}", row.order)));
      CAPTURE(row.integrator);
      CAPTURE(row.dt_s);
      if (i % 3 == 0) CHECK(std::abs(peak / ref_peak - 1.0) < 0.01);     // at the shipped dt
      if (i % 3 == 2) CHECK(row.nrmse_pct < 0.5 * study.rows[i - 2].nrmse_pct);  // converges
    }
  }
}

TEST_CASE("a yielding structure's run is bit-identical on memq and udpm") {
  const auto s = rths::scenario::LoadScenario(kReference, {"run.duration_s=3", "structure.integrator=alpha_os",
                                                           "structure.specimen_count=1"});
  const fs::path memq = rths_test::TempDir("nonlinear_memq");
  REQUIRE(rths_test::RunMemq({s}, memq).code == 0);
  const std::string digest = rths::io::PayloadDigest(rths::io::ReadRunLog((memq / "log.lcm").string()));
  if (!rths_test::UdpmAvailable()) FAIL("udpm cannot run on this host");
  const fs::path udpm = rths_test::TempDir("nonlinear_udpm");
  std::string output;
  REQUIRE(rths_test::RunCli(kReference + " --transport udpm --set run.duration_s=3 --set structure.integrator=alpha_os "
                                         "--set structure.specimen_count=1 --out " + (udpm / "run").string(),
                            &output) == 0);
  CAPTURE(output);
  CHECK(rths::io::PayloadDigest(rths::io::ReadRunLog((udpm / "run" / "log.lcm").string())) == digest);
  CHECK(Summary(udpm / "run").contains("structure_hysteretic_energy_kN_mm"));
}

TEST_CASE("[structure.spring] and structure.integrator: bad values are refused naming the key") {
  CHECK(LoadError({}).empty());
  CHECK(LoadError({"structure.spring.alpha=1.5"}).find("structure.spring.alpha") != std::string::npos);
  CHECK(LoadError({"structure.spring.gamma=0.9"}).find("structure.spring.") != std::string::npos);  // beta >= |gamma|
  CHECK(LoadError({"structure.alpha_os_alpha=-0.5"}).find("structure.alpha_os_alpha") != std::string::npos);
  CHECK(LoadError({"structure.integrator=alpha_os", "structure.substeps=4"}).find("structure.substeps") !=
        std::string::npos);
  CHECK(LoadError({"structure.integrator=rk4_unit_delay"}).find("rk4_unit_delay runs linear structures only") !=
        std::string::npos);
  CHECK(LoadError({"structure.integrator=euler"}).find("structure.integrator") != std::string::npos);
  CHECK(LoadError({"structure.specimen_count=-1"}).find("structure.specimen_count") != std::string::npos);
  // A matrix file (M, K, C) has no story springs: the stepped integrators need a shear-building file.
  const std::string benchmark = std::string(RTHS_SOURCE_DIR) + "/scenarios/fig11_base.toml";
  try {
    rths::scenario::LoadScenario(benchmark, {"structure.integrator=cr"});
    FAIL("cr on a matrix file loaded");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("structure.integrator: cr needs story springs") != std::string::npos);
  }
  // rk4_unit_delay on the yielding 9-story building: refused.
  try {
    rths::scenario::LoadScenario(std::string(RTHS_SOURCE_DIR) + "/scenarios/nonlinear/ohtori9_semiactive.toml",
                                 {"structure.integrator=rk4_unit_delay"});
    FAIL("rk4_unit_delay on a yielding building loaded");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("rk4_unit_delay runs linear structures only") != std::string::npos);
  }
}
