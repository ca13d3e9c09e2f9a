// Yielding numerical substructures through the lockstep (issue 44): the shipped reference SDOF
// (scenarios/nonlinear/reference_sdof.toml) with every integrator gives the CVODE reference's peak,
// residual and hysteretic energy in summary.json; a yielding run is bit-identical on memq and udpm;
// [structure.spring] and structure.integrator are validated with the key named.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/run_log.h"
#include "models/structure_file.h"
#include "models/structure_reference.h"
#include "scenario/scenario.h"
#include "signal/history.h"
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
  const auto ref = rths::models::SolveReference(rths::models::NonlinearSdofFromScenario(s.structure), s.run.dt_s, ground);
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
  // A structure file has no story springs yet: the stepped integrators are for the SDOF.
  const std::string benchmark = std::string(RTHS_SOURCE_DIR) + "/scenarios/benchmark/case1_example.toml";
  try {
    rths::scenario::LoadScenario(benchmark, {"structure.integrator=cr"});
    FAIL("cr on a structure file loaded");
  } catch (const rths::Error& e) {
    CHECK(std::string(e.what()).find("structure.integrator") != std::string::npos);
  }
}
