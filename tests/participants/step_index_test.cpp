// Step indices (docs/lockstep.md): feed known sequences through whole lockstep runs and check
// every row of the table by recomputing it offline, bit for bit, from the logged inputs.
#include <doctest/doctest.h>

#include <cmath>

#include "control/feedforward.h"
#include "io/run_log.h"
#include "models/linear_rig.h"
#include "models/servo_linear.h"
#include "models/structure.h"
#include "signal/history.h"
#include "run_support.h"
#include "test_support.h"

using namespace rths_test;
using rths::io::ReadRunLog;

TEST_CASE("predefined mode: u_k = r_k, y_k is the ZOH response to u_0..u_{k-1}") {
  const auto dir = TempDir("index_predefined");
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 0.25
[structure]
mode = "predefined"
[structure.desired]
kind = "blwn"
band_hz = 15.0
rms_mm = 0.595
seed = 3
[controller]
kind = "none"
[plant]
actuator = "avg"
specimen = "none"
[semiactive]
mode = "constant"
current_A = 1.25
)").string());
  REQUIRE(RunMemq({s}, dir).code == 0);
  const auto log = ReadRunLog((dir / "log.lcm").string());
  const std::int64_t n = s.steps();
  REQUIRE(log.CompleteSteps() == n);

  const auto r = rths::signal::MakeSignal(s.structure.desired, s.run.dt_s, n);
  const auto servo = rths::models::LinearServo::Make(s.plant.actuator, s.run.dt_s);
  rths::models::LinearServoState z;
  rths::control::ExtrapolationState ex;
  int mismatches = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto& d = log.desired[k];
    const auto& c = log.command[k];
    const auto& m = log.measured[k];
    const auto& i = log.current[k];
    const auto der = rths::control::StepDerivatives(&ex, r[k], s.run.dt_s);
    // desired_t k: r_k of the record, derivatives by Eqs. 20-22 from r_0..r_k.
    mismatches += d.r_mm != r[k] || d.rd_mm_s != der.rd || d.rdd_mm_s2 != der.rdd ||
                  d.rddd_mm_s3 != der.rddd;
    // command_t k: none means u_k = r_k.
    mismatches += c.u_mm != d.r_mm;
    // measured_t k: y_k = C z_k, z_k after u_0..u_{k-1}; current applied over the previous step.
    mismatches += m.y_mm != rths::models::Output(servo, z);
    mismatches += m.current_A != (k == 0 ? 0.0 : 1.25);
    mismatches += i.i_cmd_A != 1.25;
    rths::models::Step(servo, &z, c.u_mm);
  }
  CHECK(mismatches == 0);
  // A one-step shift would be caught: y_k is not the response including u_k.
  rths::models::LinearServoState z2;
  int shifted_equal = 0;
  for (std::int64_t k = 1; k < n; ++k) {
    rths::models::Step(servo, &z2, log.command[k - 1].u_mm);
    shifted_equal += log.measured[k - 1].y_mm == rths::models::Output(servo, z2);
  }
  CHECK(shifted_equal < n / 10);
}

TEST_CASE("rths mode: x_{k+1} comes from the force measured at step k; f_k from u_{k-1}, i_{k-1}") {
  const auto dir = TempDir("index_rths");
  const auto s = rths::scenario::LoadScenario(WriteScenario(dir, R"(
[run]
duration_s = 0.25
[structure.ground]
kind = "blwn"
band_hz = 30.0
rms_mm_s2 = 2000.0
seed = 5
[controller]
kind = "ff"
model = "avg"
[semiactive]
mode = "passive_on"
)").string());
  REQUIRE(RunMemq({s}, dir).code == 0);
  const auto log = ReadRunLog((dir / "log.lcm").string());
  const std::int64_t n = s.steps();
  REQUIRE(log.CompleteSteps() == n);

  // Integrator offline: central difference driven by the logged forces.
  const auto ag = rths::signal::MakeSignal(s.structure.ground, s.run.dt_s, n);
  const auto structure = rths::models::LinearStructure::Sdof(
      s.structure.mass_kg, s.structure.frequency_hz, s.structure.damping_ratio, s.structure.specimen_count);
  const auto cd = rths::models::CentralDifference::Make(structure, s.run.dt_s);
  auto st = rths::models::MakeState(cd);
  // Plant offline: the rig driven by the logged commands and currents.
  const auto rig = rths::models::LinearRig::Make(s.plant.actuator, s.run.dt_s, true,
                                                 rths::models::MrDamperParams::Table3(), s.plant.ode_rtol);
  rths::models::LinearRigStepper stepper(rig);
  rths::models::LinearRigState ps{};
  int mismatches = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    if (k > 0) {
      rths::models::Advance(cd, &st, ag[k - 1], log.measured[k - 1].f_kN);  // x_k from f_{k-1}
      stepper.Step(&ps, log.command[k - 1].u_mm, log.current[k - 1].i_cmd_A);
    }
    mismatches += log.desired[k].r_mm != st.x[0];
    mismatches += log.desired[k].ground_acc_mm_s2 != ag[k];
    mismatches += log.measured[k].y_mm != rths::models::MeasuredDisplacementMm(rig, ps);
    const double i_prev = k == 0 ? 0.0 : log.current[k - 1].i_cmd_A;
    mismatches += log.measured[k].f_kN != rths::models::MeasuredForceKn(rig, ps, i_prev);
    mismatches += log.current[k].i_cmd_A != s.semiactive.max_current_A;
  }
  CHECK(mismatches == 0);
  // The damper did work: forces are far from zero, so the check above is not vacuous.
  double peak = 0.0;
  for (std::int64_t k = 0; k < n; ++k) peak = std::max(peak, std::abs(log.measured[k].f_kN));
  CHECK(peak > 1.0);
}
