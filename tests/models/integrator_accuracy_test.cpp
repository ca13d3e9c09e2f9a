// The structural integrators' measured accuracy on the issue-44 reference SDOF (Bouc-Wen, El Centro
// NS at 1.0 x, 2 kHz) against the CVODE reference: order of convergence at dt, dt/2, dt/4 and the
// peak displacement at the RTHS dt (models/integrator_accuracy.h). Prints the table of
// docs/structures.md ("Measured accuracy"): build/bin/integrator_accuracy_test -s
#include <cmath>
#include <string>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "models/integrator_accuracy.h"

using namespace rths::models;

namespace {

const std::string kElCentro = std::string(RTHS_SOURCE_DIR) + "/data/ground_motion/elcentro_1940_ns_g.txt";
constexpr double kDt = 0.0005, kXy = 4.0;

std::vector<IntegratorConfig> Configs() {
  std::vector<IntegratorConfig> c(7);
  c[0].kind = IntegratorKind::kCentralDifference;
  c[1].kind = IntegratorKind::kCentralDifference, c[1].substeps = 4;
  c[2].kind = IntegratorKind::kCr;
  c[3].kind = IntegratorKind::kCr, c[3].substeps = 4;
  c[4].kind = IntegratorKind::kAlphaOs, c[4].alpha = -0.05;
  c[5].kind = IntegratorKind::kNewmarkImplicit, c[5].newton_iterations = 1;
  c[6].kind = IntegratorKind::kNewmarkImplicit, c[6].newton_iterations = 2;
  return c;
}

AccuracyStudy Study(double start_s) {
  const AccuracyStudy s = MeasureAccuracy(
      ReferenceSdof(), kDt, [=](double h) { return ElCentroGround(kElCentro, 1.0, h, 40.0, start_s); }, 3,
      Configs());
  const double peak_ref = s.reference_summary.peak_drift_mm[0];
  MESSAGE(fmt::format("{:<24}{:>10} {:>9} {:>9} {:>11} {:>9} {:>9} {:>7} {:>6}", "integrator", "dt [s]", "peak [mm]",
                      "ductility", "resid. [mm]", "E_h [kNmm]", "NRMSE [%]", "order", "|r| kN"));
  MESSAGE(fmt::format("{:<24}{:>10.6f} {:>9.4f} {:>9.3f} {:>11.4f} {:>9.2f} {:>9} {:>7} {:>6}",
                      "reference (" + s.reference.method + ")", kDt, peak_ref, peak_ref / kXy,
                      s.reference_summary.residual_drift_mm[0], s.reference.hysteretic_energy_kN_mm, "-", "-",
                      "-"));
  for (const AccuracyRow& r : s.rows)
    MESSAGE(fmt::format("{:<24}{:>10.6f} {:>9.4f} {:>9.3f} {:>11.4f} {:>9.2f} {:>9.5f} {:>7.2f} {:>6.0e}",
                        r.integrator, r.dt_s, r.summary.peak_drift_mm[0], r.summary.peak_drift_mm[0] / kXy,
                        r.summary.residual_drift_mm[0], r.hysteretic_energy_kN_mm, r.nrmse_pct, r.order,
                        r.max_residual_kN));
  return s;
}

// At the RTHS dt (every third row): peak and energy within 1 % of the reference.
void CheckRthsStep(const AccuracyStudy& s) {
  const double peak_ref = s.reference_summary.peak_drift_mm[0];
  for (std::size_t i = 0; i < s.rows.size(); i += 3) {
    const AccuracyRow& r = s.rows[i];
    CAPTURE(r.integrator);
    CHECK(std::abs(r.summary.peak_drift_mm[0] / peak_ref - 1) < 0.01);
    CHECK(r.hysteretic_energy_kN_mm == doctest::Approx(s.reference.hysteretic_energy_kN_mm).epsilon(0.01));
  }
}

}  // namespace

TEST_CASE("reference SDOF, El Centro from its first row: peaks within 1 %; cd and cr lose order to the start") {
  const AccuracyStudy s = Study(0.0);
  const double peak_ref = s.reference_summary.peak_drift_mm[0];
  CHECK(peak_ref / kXy > 1.5);  // it yields: ductility about 2
  CHECK(s.reference.hysteretic_energy_kN_mm > 1000.0);
  CheckRthsStep(s);
  // The record's first row is 0.0063 g at t = 0: the structure starts at rest under a nonzero
  // acceleration. alpha_os and newmark_implicit solve a_0 from that equilibrium and stay second
  // order; central_difference keeps today's start (x_{-1} = x_0, as if a_0 = 0: a velocity error
  // of dt a_g,0 / 2, first order), and cr loses order from this start too (its x_1 = dt^2 alpha a_0
  // is not the exact dt^2 a_0 / 2): their measured orders fall towards 1 as the start's error
  // dominates (1.66, 1.39 and 1.95, 1.77; with 4 sub-steps 1.12, 1.04 and 1.50, 1.23). From a
  // record that starts at rest they are second order (the next test).
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    if (i % 3 == 0) continue;
    const AccuracyRow& r = s.rows[i];
    CAPTURE(r.integrator);
    CAPTURE(r.dt_s);
    const bool starts_exactly = r.integrator.rfind("alpha_os", 0) == 0 || r.integrator.rfind("newmark", 0) == 0;
    CHECK(r.order > (starts_exactly ? 1.8 : 0.9));
    CHECK(r.order < 2.3);
    if (!starts_exactly && r.integrator.find(" x") == std::string::npos && i % 3 == 2) CHECK(r.order < 1.85);
  }
}

TEST_CASE("reference SDOF, El Centro ramped from rest over its first 0.02 s: every integrator is second order") {
  const AccuracyStudy s = Study(0.02);
  CheckRthsStep(s);
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    if (i % 3 == 0) continue;
    const AccuracyRow& r = s.rows[i];
    CAPTURE(r.integrator);
    CAPTURE(r.dt_s);
    CHECK(r.order > 1.75);
    CHECK(r.order < 2.3);
  }
}
