#pragma once
/// @file The damper current of a scheduled semiactive mode (Table 2's pulse among them), as a
/// pure function of the step index.
#include <cstdint>

#include "control/clipped_optimal.h"

namespace rths::control {

/// The current command of a scheduled mode at step k [A]: passive_off 0; passive_on
/// max_current_A; constant current_A; pulse max_current_A for the first round(duty N) steps of
/// every period of N = round(1 / (pulse_hz dt)) steps, else 0 (Table 2's 0.5 Hz, 50 % pulse);
/// random_pulse the same with pulse j at max_current_A x U_j, U_j in [0, 1) a hash of (pulse_seed, j).
/// Throws rths::Error for a mode that is not a schedule.
class CurrentSchedule {
 public:
  /// `dt_s`: the step [s].
  CurrentSchedule(const SemiactiveConfig& cfg, double dt_s);
  /// The current of step k [A].
  double At(std::int64_t k) const;

 private:
  double on_A_ = 0.0;
  std::int64_t period_ = 1, on_steps_ = 1;
  bool random_ = false;    ///< "random_pulse": each pulse at on_A_ x U[0, 1) of (seed_, pulse index)
  std::uint64_t seed_ = 0;
};

}  // namespace rths::control
