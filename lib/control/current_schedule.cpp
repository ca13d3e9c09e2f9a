#include "control/current_schedule.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace rths::control {

CurrentSchedule::CurrentSchedule(const SemiactiveConfig& cfg, double dt_s) {
  if (cfg.mode == SemiactiveMode::kPassiveOff) {
    on_A_ = 0.0;
  } else if (cfg.mode == SemiactiveMode::kPassiveOn) {
    on_A_ = cfg.max_current_A;
  } else if (cfg.mode == SemiactiveMode::kConstant) {
    on_A_ = cfg.current_A;
  } else if (cfg.mode == SemiactiveMode::kPulse || cfg.mode == SemiactiveMode::kRandomPulse) {
    on_A_ = cfg.max_current_A;
    random_ = cfg.mode == SemiactiveMode::kRandomPulse;
    seed_ = cfg.pulse_seed;
    period_ = std::max<std::int64_t>(2, std::llround(1.0 / (cfg.pulse_hz * dt_s)));
    on_steps_ = std::llround(cfg.pulse_duty * static_cast<double>(period_));
  } else {
    throw Error("semiactive.mode", "'" + std::string(NameOf(kSemiactiveModeNames, cfg.mode)) +
                                       "' is not a schedule (allowed: passive_off, passive_on, constant, pulse, random_pulse)");
  }
  if (cfg.mode != SemiactiveMode::kPulse && cfg.mode != SemiactiveMode::kRandomPulse) on_steps_ = period_;
}

double CurrentSchedule::At(std::int64_t k) const {
  if (k % period_ >= on_steps_) return 0.0;
  if (!random_) return on_A_;
  // splitmix64 of (seed, pulse index): a pure function of k, so every participant and replay
  // agrees without carrying generator state.
  std::uint64_t z = seed_ + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(k / period_ + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return on_A_ * static_cast<double>(z >> 11) * 0x1.0p-53;
}

}  // namespace rths::control
