#pragma once
/// @file procs/plant's participant: the loading system and the "physical" specimen.
/// Step k answer: measured_t k = sensor readings at t_k, computed from the state after holding
/// command_t k-1 (u_{k-1}) and current_t k-1 (i_{k-1}) over [t_{k-1}, t_k) (zero-order hold,
/// as the D/A converters do). measured_t 0 is the state at rest, sent at GO. The plant answers
/// as soon as both inputs of the interval are in, so measured_t k+1 is usually ready before the
/// clock requests step k+1. Its wiring is the plant's row of the step table (lockstep/step_table.h,
/// docs/lockstep.md).
///
/// plant.kind = "ideal" (the pure numerical simulation): measured_t k is answered from desired_t k
/// (y_k = r_k) and current_t k-1 instead; measured_t 0 waits for desired_t 0 (docs/lockstep.md,
/// footnote).
///
/// The rig is plant.kind's (models::MakeRig: "linear", Eqs. 28-30; "physical", docs/models.md
/// section 5; "benchmark", docs/benchmark.md; docs/plant.md). measured_t k carries y_k [mm], f_k
/// [kN] (plus the scenario's sensor noise, plant.noise_*_rms: on y before the benchmark's A/D
/// converter when its DAQ is on) and current_A = the effective damper current i_c(t_k) [A] (after
/// Eq. 40 and the 75 Hz low-pass when plant.current_dynamics; 0 at k = 0; always 0 for "benchmark").
#include <memory>

#include "lockstep/step_participant.h"
#include "models/rig.h"
#include "rths/measured_t.hpp"
#include "scenario/scenario.h"
#include "signal/random.h"

namespace rths::participants {

class Plant final : public lockstep::StepAnswerer<rths::measured_t> {
 public:
  /// `wiring`: the run's (WiringOf(s), or a replay's); its plant row must be "ideal" exactly when
  /// plant.kind is (throws rths::Error otherwise).
  Plant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, const lockstep::Wiring& wiring,
        lockstep::Faults faults = {});

 protected:
  bool Compute(std::int64_t k, const lockstep::StepInputs& in, rths::measured_t* out) override;

 private:
  const std::unique_ptr<models::Rig> rig_;
  const double noise_y_mm_;
  const double noise_f_kN_;
  signal::GaussianState noise_;
};

}  // namespace rths::participants
