#pragma once
/// @file procs/semiactive's participant: the damper current command.
/// Step k: desired_t k (structure state) + measured_t k (y_k, f_k)  ->  current_t k, held by the
/// plant over [t_k, t_{k+1}): it first shows in measured_t k+1. See docs/lockstep.md.
/// A scheduled current (passive-off 0 A, passive-on, a constant, or the pulse of Table 2), or
/// clipped-optimal control (control/clipped_optimal.h: it uses the absolute accelerations of
/// sample k-1 carried by desired_t k and the forces of samples k-1 and k).
#include <memory>
#include <optional>

#include "control/clipped_optimal.h"
#include "participants/step_participant.h"
#include "rths/current_t.hpp"
#include "scenario/scenario.h"

namespace rths::participants {

/// The current command of a scheduled mode at step k [A]: passive_off 0; passive_on
/// max_current_A; constant current_A; pulse max_current_A for the first round(duty N) steps of
/// every period of N = round(1 / (pulse_hz dt)) steps, else 0 (Table 2's 0.5 Hz, 50 % pulse);
/// random_pulse the same with pulse j at max_current_A x U_j, U_j in [0, 1) a hash of (pulse_seed, j).
/// Throws rths::Error for a mode that is not a schedule.
class CurrentSchedule {
 public:
  CurrentSchedule(const control::SemiactiveConfig& cfg, double dt_s);
  double At(std::int64_t k) const;

 private:
  double on_A_ = 0.0;
  std::int64_t period_ = 1, on_steps_ = 1;
  bool random_ = false;    ///< "random_pulse": each pulse at on_A_ x U[0, 1) of (seed_, pulse index)
  std::uint64_t seed_ = 0;
};

class Semiactive final : public DesiredMeasuredParticipant<rths::current_t> {
 public:
  Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, lockstep::Faults faults = {});

 protected:
  void Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
               rths::current_t* out) override;

 private:
  std::optional<CurrentSchedule> schedule_;           ///< scheduled modes
  std::unique_ptr<control::ClippedOptimal> clipped_;  ///< "clipped_optimal"
  double f_prev_kN_ = 0.0;                            ///< force of one damper at step k-1
};

}  // namespace rths::participants
