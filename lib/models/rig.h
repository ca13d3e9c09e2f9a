#pragma once
/// @file One interface for the plant participant's loading system + specimen: the linear rig
/// (Eqs. 28-30 with the MR damper, lib/models/linear_rig.h) or the physics-based rig (docs/models.md
/// section 5, lib/models/servo_physical.h), both with the optional current dynamics (Eq. 40 and
/// the 75 Hz low-pass, lib/models/current_driver.h), or the control plant of the RTHS benchmark
/// problem (lib/models/benchmark_rig.h). Units: mm, kN, A, s (docs/units.md).
///
/// Step indices (docs/lockstep.md): after k calls of Step() the rig is at sample k; y_mm(),
/// f_kN() and current_A() are the sensor readings at t_k, made from the state after holding
/// u_{k-1} and i_{k-1} over [t_{k-1}, t_k). At k = 0 the rig is at rest and current_A() is 0.
///
/// Initial current: with current dynamics, the driver starts at the steady state of the first
/// commanded current i_0 (the current is set before the test starts, as in the lab), so a
/// constant current stays exactly constant and equals the commanded one from k = 1 on.
#include <cstdint>
#include <memory>
#include <string>
#include "models/benchmark_rig.h"
#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/rig_effects.h"
#include "models/servo_linear.h"
#include "models/servo_physical.h"
#include "core/names.h"

namespace rths::models {

/// The loading system (PlantConfig::kind): the linear three-pole model, the servovalve / oil
/// column / piston model ("physical" in files: docs/models.md section 5), ideal tracking, or the
/// RTHS benchmark's control plant ("benchmark": docs/benchmark.md).
enum class PlantKind { kLinear, kPhysical, kIdeal, kBenchmark };
inline constexpr std::array<Named<PlantKind>, 4> kPlantKindNames = {{{PlantKind::kLinear, "linear"},
                                                                     {PlantKind::kPhysical, "physical"},
                                                                     {PlantKind::kIdeal, "ideal"},
                                                                     {PlantKind::kBenchmark, "benchmark"}}};
/// The specimen on the actuator (PlantConfig::specimen).
enum class Specimen { kMrDamper, kNone };
inline constexpr std::array<Named<Specimen>, 2> kSpecimenNames = {
    {{Specimen::kMrDamper, "mr_damper"}, {Specimen::kNone, "none"}}};

/// "Physical" substructure and loading system (procs/plant).
struct PlantConfig {
  /// "linear": the three-pole model `actuator` (Eqs. 28-30), ZOH-discretised, unaffected by the
  /// specimen; "physical": the servovalve / oil column / piston model of docs/models.md section 5
  /// loaded by the damper force (control-structure interaction); "ideal": the pure numerical
  /// simulation, a loading system that tracks perfectly (y_k = r_k, the damper driven by the
  /// desired motion; answers measured_t k from desired_t k: docs/lockstep.md, footnote);
  /// "benchmark": the fifth-order control plant Gp of the RTHS benchmark problem (Silva et al.
  /// 2020) with its experimental substructure as the specimen, `benchmark` below
  /// (lib/models/benchmark_rig.h; specimen, damper and current settings do not apply).
  PlantKind kind = PlantKind::kLinear;
  ServoModel3 actuator{};              ///< "linear": servohydraulic model
  PhysicalActuatorConfig physical{};   ///< "physical": its parameters
  Specimen specimen = Specimen::kMrDamper;  ///< "mr_damper" (Eqs. 32-39, Table 3) | "none"
  /// Damper current dynamics: the driver lag of Eq. 40 and a 75 Hz second-order Butterworth
  /// low-pass between the commanded and the effective current. false: effective = commanded.
  bool current_dynamics = true;
  /// The form of those dynamics, `[plant.current_driver]` (models/current_driver.h): Eq. 40 + the
  /// low-pass (default) or the first-order filter of Spencer et al. (1997) with its eta.
  CurrentDriverParams current_driver{};
  /// "benchmark": the plant's constants (SI) and DAQ, `[plant.benchmark]` and `[plant.benchmark.daq]`.
  BenchmarkRigConfig benchmark{};
  double noise_y_mm_rms = 0.0;         ///< Gaussian sensor noise on y [mm], [0, 10]
  double noise_f_kN_rms = 0.0;         ///< Gaussian sensor noise on f [kN], [0, 100]
  std::uint64_t noise_seed = 7;
  double ode_rtol = 1e-8;              ///< the step integrator's relative tolerance (ARKODE by default; scenario key plant.ode_rtol, old name plant.cvode_rtol), (0, 1e-2]
  /// The Spencer MR damper of every rig (`[plant.damper]`, Eqs. 32-39; default Table 3).
  MrDamperParams damper{};
  /// Rig mode (docs/rig_mode.md): effects of the library switched on, `[plant.effects.<name>]`
  /// (kind = "linear" only). Empty: the nominal plant.
  EffectSet effects{};
  /// Rig mode, `[plant.effects.load_coupling] same_sample`: true (default) couples with the force
  /// of the same sample, y_k = x_k - c f_k, solved per step, as a real series compliance does:
  /// stable for any compliance (what the diagnosis fits, from the measured f_k); false with the
  /// force of the previous sample, y_k = x_k - c f_{k-1}, cheaper, but the one-sample loop diverges
  /// with the stiff damper once c (alpha A + 2 B / dt) > 1 (c > 7e-4 mm/kN at 2.5 A; docs/rig_mode.md).
  bool load_coupling_same_sample = true;
  /// Rig mode: disturbances outside the library, `[plant.unmodelled]` (kind = "linear" only).
  UnmodelledConfig unmodelled{};
  /// true if the plant runs in rig mode (effects or unmodelled disturbances on).
  bool RigMode() const { return !effects.Empty() || !unmodelled.Empty(); }
  bool operator==(const PlantConfig&) const = default;
};

class Rig {
 public:
  virtual ~Rig() = default;
  /// Sample k -> k+1: holds the command u_mm [mm] and the commanded damper current i_cmd_A [A]
  /// over [t_k, t_{k+1}). Allocates nothing. Throws rths::Error if the integration fails.
  virtual void Step(double u_mm, double i_cmd_A) = 0;
  /// Measured actuator displacement y_k [mm].
  virtual double y_mm() const = 0;
  /// The displacement reading y_k [mm] with the sensor noise noise_mm [mm] added where the sensor
  /// adds it: y_mm() + noise_mm, or for "benchmark" with its DAQ on, before the A/D converter.
  virtual double MeasuredYMm(double noise_mm) const { return y_mm() + noise_mm; }
  /// Measured specimen force f_k [kN] (0 without a specimen).
  virtual double f_kN() const = 0;
  /// Effective damper current i_c(t_k) [A] (after Eq. 40 and the low-pass if they are on).
  virtual double current_A() const = 0;
  /// Sample index k (number of Step() calls so far).
  virtual std::int64_t k() const = 0;
  /// true for the "ideal" loading system (plant.kind = "ideal"): Step()'s first argument is then
  /// the desired displacement r_k of the step's *end* (not a command held from its start), and
  /// the plant answers measured_t k from desired_t k (docs/lockstep.md, footnote).
  virtual bool TracksDesired() const { return false; }
  /// "ideal" only: the position at k = 0 (r_0, at rest). Others ignore it (they start at rest at 0).
  virtual void StartAt(double /*x_mm*/) {}
};

/// "ideal" (the pure numerical simulation: the damper model driven by the desired motion, no actuator): a
/// loading system that tracks perfectly. Step(r_k, i_{k-1}) drives the damper with x(t) linear from
/// r_{k-1} to r_k over [t_{k-1}, t_k] (velocity (r_k - r_{k-1}) / dt) at the current i_{k-1}
/// (through the current dynamics if on), so y_k = r_k exactly and f_k is the damper force at t_k
/// (x = r_k, x' = that velocity).
///
/// The rig that `plant` describes ("linear" | "physical" | "ideal"; specimen "mr_damper" | "none";
/// current_dynamics; ode_rtol; the damper parameters plant.damper), stepping at dt_s [s];
/// "benchmark": the benchmark's plant of plant.benchmark (specimen, damper and current settings
/// ignored; current_A() is 0).
/// With effects or unmodelled disturbances on (plant.RigMode()), the rig mode of
/// lib/models/effect_rig.h, which needs kind "linear"; otherwise the nominal rigs, unchanged.
/// Throws rths::Error for a bad kind or value.
std::unique_ptr<Rig> MakeRig(const models::PlantConfig& plant, double dt_s);

/// plant.specimen: true for "mr_damper", false for "none"; throws rths::Error otherwise.
bool HasDamper(const models::PlantConfig& plant);

}  // namespace rths::models
