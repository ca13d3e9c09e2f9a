#include "participants/semiactive.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "models/structure_file.h"
#include "participants/factory.h"

namespace rths::participants {

CurrentSchedule::CurrentSchedule(const control::SemiactiveConfig& cfg, double dt_s) {
  if (cfg.mode == control::SemiactiveMode::kPassiveOff) {
    on_A_ = 0.0;
  } else if (cfg.mode == control::SemiactiveMode::kPassiveOn) {
    on_A_ = cfg.max_current_A;
  } else if (cfg.mode == control::SemiactiveMode::kConstant) {
    on_A_ = cfg.current_A;
  } else if (cfg.mode == control::SemiactiveMode::kPulse || cfg.mode == control::SemiactiveMode::kRandomPulse) {
    on_A_ = cfg.max_current_A;
    random_ = cfg.mode == control::SemiactiveMode::kRandomPulse;
    seed_ = cfg.pulse_seed;
    period_ = std::max<std::int64_t>(2, std::llround(1.0 / (cfg.pulse_hz * dt_s)));
    on_steps_ = std::llround(cfg.pulse_duty * static_cast<double>(period_));
  } else {
    throw Error("semiactive.mode", "'" + std::string(NameOf(control::kSemiactiveModeNames, cfg.mode)) +
                                       "' is not a schedule (allowed: passive_off, passive_on, constant, pulse, random_pulse)");
  }
  if (cfg.mode != control::SemiactiveMode::kPulse && cfg.mode != control::SemiactiveMode::kRandomPulse)
    on_steps_ = period_;
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

Semiactive::Semiactive(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm,
                       lockstep::Faults faults)
    : DesiredMeasuredParticipant("semiactive", std::move(id), TimingOf(s), lcm, std::move(faults),
                                 lockstep::kChCurrent, lockstep::kCurrent, PlantAnswersCommand(s)),
      f_prev_kN_(0.0) {
  if (s.semiactive.mode == control::SemiactiveMode::kClippedOptimal) {
    const control::ClippedOptimalOptions o{s.semiactive.r_weight, s.semiactive.noise_ratio,
                                           s.semiactive.capacity_kN, s.semiactive.max_current_A};
    clipped_ = std::make_unique<control::ClippedOptimal>(control::DesignClippedOptimal(
        models::StructureFromScenario(s.structure, s.path), s.run.dt_s, o));
  } else {
    schedule_.emplace(s.semiactive, s.run.dt_s);
  }
}

void Semiactive::Compute(std::int64_t k, const rths::desired_t& d, const rths::measured_t& m,
                         rths::current_t* out) {
  if (clipped_) {
    if (d.n_dof != clipped_->design().n) throw Error("semiactive", "desired_t carries the wrong number of DOFs");
    out->i_cmd_A = clipped_->Step(k, d.abs_acc_mm_s2.data(), f_prev_kN_, m.f_kN);
    out->f_desired_kN = clipped_->desired_force_kN();
    f_prev_kN_ = m.f_kN;
    return;
  }
  out->i_cmd_A = schedule_->At(k);
  out->f_desired_kN = 0.0;
}

}  // namespace rths::participants
