#pragma once
/// @file plant.kind = "benchmark": the control plant of the RTHS benchmark problem (Silva et al.
/// 2020; lib/models/benchmark_plant.h, docs/benchmark.md) as the loading system of procs/plant,
/// with the load cell of its experimental substructure and an optional data-acquisition (DAQ)
/// converter on the command and on the measured displacement. Units at this edge: mm, kN, s
/// (docs/units.md); the plant inside is SI (m, N, kg) and every conversion is written out below.
///
/// Step indices (docs/lockstep.md, as every models::Rig): after k calls of Step() the rig is at
/// sample k; the readings at t_k come from the plant's state z_k, which holds the commands
/// u_0 .. u_{k-1}, each held over its step (zero-order hold, BenchmarkPlant's exact ZOH).
///
/// One step k -> k+1 with the command u_k [mm]:
///
///     u'_k  = D(u_k)                                 DAQ (identity when off)
///     z_{k+1} = Phi z_k + Gamma 1e-3 u'_k             StepMm: the plant Gp, u'_k held over [t_k, t_{k+1})
///
/// and the readings at t_k, z_k = [y, y', y'', y''', y''''] [m, m/s, m/s^2, ...]:
///
///     y_k [mm] = D(1e3 z_k[0] + n_y)                 LVDT (+ sensor noise n_y [mm]) through the DAQ
///     f_k [kN] = 1e-3 (m_e z_k[2] + c_e z_k[1] + k_e z_k[0])     load cell [N -> kN], not digitised
///
/// f_k is the force the experimental substructure (m_e, c_e = 2 zeta_e sqrt(m_e k_e), k_e of
/// the plant's constants, the Gest of Gp) puts on the actuator; positive f resists positive
/// displacement, the sign convention of lib/models/structure.h. At DC f = k_e y.
///
/// The DAQ D (BenchmarkDaqConfig, when enabled): displacement x [mm] to volts
/// v = volts_per_m 1e-3 x, clipped to [-saturation_V, saturation_V], quantised by a mid-tread
/// two's-complement converter of `bits` bits (step q = 2 saturation_V / 2^bits, codes
/// round(v / q) limited to [-2^(bits-1), 2^(bits-1) - 1], so 0 V is a level and the top code is
/// saturation_V - q), and back to millimetres. The same D serves the D/A converter of the command
/// and the A/D converter of y.
///
/// The specimen of this kind is the benchmark's experimental substructure inside Gp: the MR
/// damper, plant.specimen, plant.damper, plant.current_dynamics and the damper current do not
/// apply (current_A() is 0; the semiactive participant still runs and its current is ignored).
#include <cstdint>
#include <string_view>

#include "models/benchmark_plant.h"

namespace rths::models {

/// The benchmark's optional converters (`[plant.benchmark.daq]`). The benchmark specifies the
/// range (+/-3.8 V) and the resolution (18 bits) but not the transducer gain: we assume
/// 100 V/m (0.1 V/mm), which maps the range to +/-38 mm of stroke (the benchmark's
/// displacements stay within a few millimetres) and gives a step of 0.29 micrometres, far below
/// the displacement noise (16 micrometres RMS at 4096 Hz). docs/benchmark.md.
struct BenchmarkDaqConfig {
  bool enabled = false;        ///< false: command and y pass unchanged
  double volts_per_m = 100.0;  ///< transducer and converter gain [V/m], > 0
  double saturation_V = 3.8;   ///< converter range +/-saturation_V [V], > 0
  int bits = 18;               ///< resolution [bits], [2, 32]
  bool operator==(const BenchmarkDaqConfig&) const = default;
};

/// `[plant.benchmark]` of a scenario: the plant's constants (SI, BenchmarkPlantParams; default:
/// the nominal plant of case 1) and the DAQ.
struct BenchmarkRigConfig {
  BenchmarkPlantParams params{};
  BenchmarkDaqConfig daq{};
  bool operator==(const BenchmarkRigConfig&) const = default;
};

/// Throws rths::Error (prefixed `where`, e.g. "scenario.toml: plant.benchmark.daq") unless
/// volts_per_m and saturation_V are finite and > 0 and bits is in [2, 32]. Checked even when
/// the DAQ is off. The message names the field and its range.
void ValidateBenchmarkDaq(const BenchmarkDaqConfig& daq, std::string_view where = "benchmark DAQ");

/// The converter's step in displacement, q / (volts_per_m 1e-3) [mm], q = 2 saturation_V / 2^bits [V]
/// (whether or not the DAQ is enabled).
double DaqStepMm(const BenchmarkDaqConfig& daq);
/// One pass through the converter D [mm -> mm] (see the file comment); x_mm itself when
/// !daq.enabled. Allocates nothing.
double DaqConvertMm(const BenchmarkDaqConfig& daq, double x_mm);

/// Immutable description of the rig: the plant at the run's step and the DAQ.
struct BenchmarkRig {
  BenchmarkPlant plant;
  BenchmarkDaqConfig daq;
  /// Validates (BenchmarkPlant::Make, ValidateBenchmarkDaq) and builds. Throws rths::Error.
  static BenchmarkRig Make(const BenchmarkRigConfig& config, double dt_s);
};

/// Per-step state at sample k: the plant's z_k.
struct BenchmarkRigState {
  BenchmarkPlantState plant;
};

/// Sample k -> k+1: D(u_mm) [mm] held over [t_k, t_{k+1}) (StepMm). Allocates nothing.
void Step(const BenchmarkRig& rig, BenchmarkRigState* s, double u_mm);
/// The actuator's true displacement 1e3 z_k[0] at t_k [mm] (before noise and the DAQ).
double TrueDisplacementMm(const BenchmarkRig& rig, const BenchmarkRigState& s);
/// The displacement reading y_k = D(true y_k + noise_mm) [mm]: the sensor noise noise_mm [mm]
/// enters before the A/D converter, as on a real transducer.
double MeasuredDisplacementMm(const BenchmarkRig& rig, const BenchmarkRigState& s, double noise_mm = 0.0);
/// The experimental substructure's force at t_k, 1e-3 (m_e y'' + c_e y' + k_e y) [kN] with y
/// and its derivatives [m, m/s, m/s^2] from z_k.
double MeasuredForceKn(const BenchmarkRig& rig, const BenchmarkRigState& s);

}  // namespace rths::models
