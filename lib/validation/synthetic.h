#pragma once
/// @file Rig records with known effects made in-process, for the diagnosis's tests and its
/// validation harness (tests/diagnosis_*_test.cpp, bench/diagnosis.cpp). Two generators:
///   - MakeRecordBlocks: the effect blocks of models/rig_effects.h around the Eq. 30 actuator
///     (exact ZOH) and a Spencer damper stepped sample by sample (RK4, 8 substeps; inside a step
///     the servo's Hermite motion plus the effects' offset interpolated linearly, as the rig mode
///     does; the current through Eq. 40 + 75 Hz), independent of the diagnosis's own force
///     predictor (which works from the noisy measured y);
///   - MakeRecordRig: the plant's rig mode (models::MakeRig with plant.effects and
///     plant.unmodelled), the same code that procs/plant runs.
/// Both: u from a band-limited white noise (signal::Blwn), the current command a random
/// staircase (levels in {0, 0.5, ..., max}, durations uniform in [hold_min_s, hold_max_s]) or
/// constant, Gaussian sensor noise of the given rms on y and f.
#include <cstdint>

#include "io/rig_record.h"
#include "models/rig_effects.h"
#include "scenario/scenario.h"

namespace rths::validation {

struct Excitation {
  double duration_s = 20.0;
  double dt_s = 0.0005;
  double band_hz = 20.0;         ///< BLWN band of the command u [Hz]
  double rms_mm = 4.0;           ///< RMS of u [mm]
  std::uint64_t seed = 1;
  double current_max_A = 2.5;    ///< staircase levels 0 .. max in steps of max / 5
  double hold_min_s = 0.2, hold_max_s = 1.0;
  bool current_constant = false; ///< true: i = current_max_A throughout
  /// >= 0: the staircase's first hold is at this level [A] (a current on at the first sample), the
  /// rest drawn as usual; < 0: the first level drawn too.
  double current_start_A = -1.0;
};

struct Truth {
  models::EffectSet effects;     ///< sensor_noise here is the record's noise
  double ripple_mm = 0.0, ripple_hz = 7.0;  ///< outside the library: y += ripple sin(2 pi f t)
  double stiffness_kN_per_mm = 0.0;         ///< outside the library: f += k y
  /// The current driver at rest (0 A) when the record starts, whatever its first command
  /// ([plant.current_driver] start = "rest"); false: at the first command's steady state.
  bool driver_at_rest = false;
  /// Outside the library: the damper's force scaled by fade_start + fade_per_s t (a damper that
  /// heats over the test; models::UnmodelledConfig).
  double fade_start = 1.0, fade_per_s = 0.0;
  std::uint64_t noise_seed = 11;
};

/// The command and current histories of an excitation.
void MakeInputs(const Excitation& ex, std::vector<double>* u_mm, std::vector<double>* i_A);

/// Record from the effect blocks (file comment). source = `name`.
io::RigRecord MakeRecordBlocks(const Excitation& ex, const Truth& truth, const std::string& name);

/// Record from the plant's rig mode: models::MakeRig(plant) with kind "linear", actuator "avg",
/// specimen mr_damper, current dynamics on, effects = truth.effects (sensor noise included),
/// unmodelled = truth's ripple / stiffness. Throws rths::Error if the rig refuses the set.
io::RigRecord MakeRecordRig(const Excitation& ex, const Truth& truth, const std::string& name);

}  // namespace rths::validation
