#pragma once
/// @file procs/plant's participant: the loading system and the "physical" specimen.
/// Step k answer: measured_t k = sensor readings at t_k, computed from the state after holding
/// command_t k-1 (u_{k-1}) and current_t k-1 (i_{k-1}) over [t_{k-1}, t_k) (zero-order hold,
/// as the D/A converters do). measured_t 0 is the state at rest, sent at GO. The plant answers
/// as soon as both inputs of the interval are in, so measured_t k+1 is usually ready before the
/// clock requests step k+1. See docs/lockstep.md.
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
#include <optional>

#include "lockstep/runtime.h"
#include "models/rig.h"
#include "rths/command_t.hpp"
#include "rths/current_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/measured_t.hpp"
#include "scenario/scenario.h"
#include "signal/random.h"

namespace rths::participants {

class Plant final : public lockstep::Participant {
 public:
  Plant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, lockstep::Faults faults = {});

 protected:
  void OnGo() override;
  /// The inputs of measured_t next_ (command_t and current_t of next_ - 1; "ideal": desired_t
  /// next_ and current_t next_ - 1), if it is due by step k.
  void ListMissing(std::int64_t k, lockstep::WantList* out) const override;

 private:
  void TryStep();
  void TryStepIdeal();
  void Publish(std::int64_t k);

  const std::unique_ptr<models::Rig> rig_;
  const double noise_y_mm_;
  const double noise_f_kN_;
  signal::GaussianState noise_;
  lockstep::StepMailbox<rths::desired_t> desired_;
  lockstep::StepMailbox<rths::command_t> command_;
  lockstep::StepMailbox<rths::current_t> current_;
  lockstep::AnswerCache cache_;
  rths::measured_t out_{};
  std::int64_t next_ = 0;  ///< next measured_t to produce
};

}  // namespace rths::participants
