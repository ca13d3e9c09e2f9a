#pragma once
/// @file Scenario: a TOML file parsed once, at the edge, into plain structs with defaults.
///
/// Units follow docs/units.md: paper units (mm, kN, s, A) everywhere; the only other edge
/// unit is mass, given in kg in the file and converted to kN s^2/mm by the components.
/// Every field has a default; LoadScenario() rejects unknown keys, wrong types and
/// out-of-range values with an rths::Error naming the file, the key and the allowed range.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "models/mr_damper.h"
#include "models/rig_effects.h"

namespace rths::scenario {

/// A three-pole servohydraulic model G(s) = K / ((s + p)(s^2 + b s + c)) (Eq. 15 with N = 3;
/// Eqs. 28-30 of the paper are presets). In a file: a preset name ("0.0A", "2.5A", "avg")
/// or a table {K = ..., p = ..., b = ..., c = ...}. All four must be > 0 (stable, minimum phase).
struct ServoModel3 {
  double K = 1.600e7;  ///< gain [1/s^3] (mm/mm at DC: K / (p c))
  double p = 151.7;    ///< real pole at s = -p [1/s]
  double b = 250.4;    ///< quadratic factor s^2 + b s + c [1/s]
  double c = 1.061e5;  ///< [1/s^2]
  std::string name = "avg";  ///< preset name, or "custom"
};
/// The paper's identified models: "0.0A" (Eq. 28), "2.5A" (Eq. 29), "avg" (Eq. 30).
/// Throws rths::Error for an unknown name.
ServoModel3 ServoPreset(std::string_view name);

/// A time history generated or read at the edge (ground acceleration or desired displacement).
struct SignalSpec {
  std::string kind = "blwn";  ///< "blwn" | "file" | "zero"
  // kind = "blwn": Gaussian white noise through an 8th-order Butterworth low-pass at band_hz,
  // scaled to rms, with the first discard_s seconds thrown away (models.md section 9).
  double band_hz = 30.0;      ///< upper band edge [Hz], (0, 0.5/dt)
  double rms = 1500.0;        ///< RMS in the signal's unit (mm/s^2 for ground, mm for desired), > 0
  std::uint64_t seed = 1;     ///< generator seed
  double discard_s = 2.0;     ///< start-up transient thrown away [s], [0, 60]
  // kind = "file": one column (values at file_dt_s) or two columns (t [s], value).
  std::string file;           ///< path, relative to the scenario file's folder (after parsing: absolute)
  double file_dt_s = 0.0;     ///< step of a one-column file [s]; 0 = the file has a time column
  double scale = 1.0;         ///< multiply the file's values by this to get the signal's unit
  /// Raised-cosine fade-in over the first taper_s seconds [s], [0, 60]: a BLWN record cut after
  /// its discarded start begins mid-motion, which would ask the actuator for a step.
  double taper_s = 0.0;
};

/// Numerical substructure (procs/integrator).
struct StructureConfig {
  std::string mode = "rths";  ///< "rths" (central difference, Eqs. 1-3) | "predefined" (r from a history)
  /// mode = "rths": "sdof" (mass, frequency, damping below) | "file" (M, K, C from `file`, a
  /// structure file: docs/structures.md; e.g. data/buildings/ohtori9_ns.txt).
  std::string kind = "sdof";
  std::string file;           ///< kind = "file": path, relative to the scenario file's folder
  int actuator_dof = 1;       ///< kind = "file": DOF the specimen acts on, 1-based (1 = first story)
  // kind = "sdof":
  double mass_kg = 20000.0;          ///< (0, 1e9]
  double frequency_hz = 5.0;         ///< natural frequency (0, 1/(pi dt)) -- central-difference limit omega dt < 2
  double damping_ratio = 0.02;       ///< [0, 1)
  double specimen_count = 1.0;       ///< measured force multiplier (18 dampers act as one) (0, 1000]
  SignalSpec ground{};               ///< ground acceleration [mm/s^2]
  // mode = "predefined": the desired displacement itself [mm].
  SignalSpec desired{"blwn", 5.0, 2.78, 1, 2.0, "", 0.0, 1.0, 0.5};
  /// How the integrator gets r', r'', r''' in predefined mode: "extrapolated" (Eqs. 20-22, the
  /// causal RTHS path) | "central" (offline, non-causal central differences of the known record).
  std::string derivatives = "extrapolated";
};

/// LQG feedback on the deviation system (Eqs. 23-27, models.md section 4). The cost is
/// sum(q e_k^2 + u_FB,k^2); the disturbance is white noise of intensity W through the
/// second-order shaping filter of Eq. 27; the measurement noise has intensity V.
struct LqgConfig {
  double q = 10.0;       ///< weight on the tracking error, (0, 1e12]
  double w_f_hz = 3.0;   ///< shaping filter frequency omega_f / 2 pi [Hz], (0, 1000]
  double xi_f = 0.7;     ///< shaping filter damping (peak), (0, 10]
  double eta_f = 0.5;    ///< shaping filter zero (roll-off), [0, 100]
  double W = 1.0;        ///< process-noise intensity, (0, 1e12]
  double V = 1.0;        ///< measurement-noise intensity, (0, 1e12]
};

/// Outer-loop tracking controller (procs/controller); Table 1 of the paper.
struct ControllerConfig {
  /// "none" (u = r) | "ff" (model inverse, Eqs. 16-22) | "poly3" (third-order polynomial
  /// extrapolation, Horiuchi 1996) | "lead" (single-pole single-zero lead compensator) |
  /// "ff_lp" (model inverse with a Butterworth low-pass, Carrion & Spencer 2007) |
  /// "bumpless_lp" (ff_lp for model_low and model_high blended by damper current) |
  /// "ff_lqg" (ff with `model` plus LQG feedback designed on `model`, Eqs. 23-27).
  std::string kind = "ff";
  ServoModel3 model{};         ///< design model for "ff", "ff_lp", "ff_lqg"
  /// models.md section 2: evaluate the feedforward half a step ahead to cancel the ZOH's
  /// half-sample lag in simulation. false = the paper's Eq. 19.
  bool half_step_ahead = false;
  double delay_ms = 9.0;        ///< "poly3", "lead": the delay compensated [ms], (0, max_delay_ms]
  double max_delay_ms = 15.0;   ///< bound on delay_ms (extrapolation amplifies noise), (0, 100]
  double lead_tp_ms = 0.5;      ///< "lead": pole time constant T_p [ms] (T_z = delay + T_p), (0, 100]
  double lp_cutoff_hz = 318.0;  ///< "ff_lp", "bumpless_lp": Butterworth cutoff [Hz], (0, 0.5/dt)
  int lp_order = 3;             ///< Butterworth order, [3, 8] (the inverse is improper by 3)
  ServoModel3 model_low{1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};   ///< "bumpless_lp": at 0 A (Eq. 28)
  ServoModel3 model_high{1.613e7, 134.2, 324.6, 1.211e5, "2.5A"};  ///< at current_high_A (Eq. 29)
  double current_high_A = 2.5;  ///< "bumpless_lp": lambda = i_eff / current_high_A, (0, 5]
  LqgConfig lqg{};              ///< "ff_lqg"
};

/// The physics-based servohydraulic actuator (models.md section 5). SI units inside, as named.
struct PhysicalActuatorConfig {
  double area_m2 = 0.0271;             ///< piston area A, (0, 1]
  double supply_pressure_Pa = 20.7e6;  ///< P_s, (0, 1e9]
  double volume_m3 = 9.26e-3;          ///< total oil volume V_t, (0, 1]
  double piston_mass_kg = 150.0;       ///< moving mass m, (0, 1e5]
  double piston_damping_N_s_m = 0.0;   ///< c_p, [0, 1e9]
  double valve_hz = 70.24;             ///< servovalve natural frequency w_v / 2 pi [Hz], (0, 1e4]
  double valve_zeta = 0.583;           ///< servovalve damping zeta_v, (0, 10]
  double kq_m3_s = 1.09e-2;            ///< flow gain K_q at full spool, (0, 10]
  double kp_per_m = 331.4;             ///< inner-loop gain K_p [1/m] (K_p K_q / A = 133.3 1/s), (0, 1e6]
  double beta_Pa = 1.172e9;            ///< effective bulk modulus beta_e, (0, 1e12]
  double leakage_m3_s_Pa = 2.693e-11;  ///< total leakage coefficient C_tot, [0, 1e-6]
};

/// Disturbances of the rig mode that are deliberately NOT in the effect library
/// (models/rig_effects.h), so that the diagnosis can be tested on its "unknown" verdict
/// (docs/rig_mode.md). All off (0) by default.
struct UnmodelledConfig {
  /// Periodic disturbance on the measured displacement (e.g. supply-pressure ripple):
  /// y_meas += ripple_mm sin(2 pi ripple_hz t_k). Amplitude [mm], [0, 10].
  double ripple_mm = 0.0;
  double ripple_hz = 0.0;            ///< [Hz], (0, 0.5/run.dt_s) when ripple_mm > 0, else [0, ...)
  /// Extra spring force on the measured force (e.g. an accumulator): f += k y, y the specimen
  /// displacement before noise [kN/mm], [-100, 100].
  double stiffness_kN_per_mm = 0.0;
  /// true if every disturbance is off.
  bool Empty() const { return ripple_mm == 0.0 && stiffness_kN_per_mm == 0.0; }
};

/// "Physical" substructure and loading system (procs/plant).
struct PlantConfig {
  /// "linear": the three-pole model `actuator` (Eqs. 28-30), ZOH-discretised, unaffected by the
  /// specimen; "physical": the servovalve / oil column / piston model of models.md section 5
  /// loaded by the damper force (control-structure interaction); "ideal": the pure numerical
  /// simulation, a loading system that tracks perfectly (y_k = r_k, the damper driven by the
  /// desired motion; answers measured_t k from desired_t k: docs/lockstep.md, footnote).
  std::string kind = "linear";
  ServoModel3 actuator{};              ///< "linear": servohydraulic model
  PhysicalActuatorConfig physical{};   ///< "physical": its parameters
  std::string specimen = "mr_damper";  ///< "mr_damper" (Eqs. 32-39, Table 3) | "none"
  /// Damper current dynamics: the driver lag of Eq. 40 and a 75 Hz second-order Butterworth
  /// low-pass between the commanded and the effective current. false: effective = commanded.
  bool current_dynamics = true;
  double noise_y_mm_rms = 0.0;         ///< Gaussian sensor noise on y [mm], [0, 10]
  double noise_f_kN_rms = 0.0;         ///< Gaussian sensor noise on f [kN], [0, 100]
  std::uint64_t noise_seed = 7;
  double cvode_rtol = 1e-8;            ///< CVODE relative tolerance, (0, 1e-2]
  /// The Spencer MR damper of every rig (`[plant.damper]`, Eqs. 32-39; default Table 3).
  models::MrDamperParams damper{};
  /// Rig mode (docs/rig_mode.md): effects of the library switched on, `[plant.effects.<name>]`
  /// (kind = "linear" only). Empty: the nominal plant.
  models::EffectSet effects{};
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
};

/// Semiactive current (procs/semiactive). Constant modes, or the 0.5 Hz pulse of Table 2;
/// clipped-optimal control later.
struct SemiactiveConfig {
  /// "passive_off" (0 A) | "passive_on" (max_current_A) | "constant" (current_A) |
  /// "pulse" (max_current_A for the first pulse_duty of every period 1/pulse_hz, then 0 A) |
  /// "clipped_optimal" (needs structure.mode = "rths").
  std::string mode = "passive_off";
  double current_A = 0.0;            ///< for "constant": [0, max_current_A]
  double max_current_A = 2.5;        ///< (0, 5]
  double pulse_hz = 0.5;             ///< "pulse": frequency [Hz], (0, 0.25/dt)
  double pulse_duty = 0.5;           ///< "pulse": fraction of the period at max current, (0, 1)
  // "clipped_optimal" (Dyke et al. 1996; docs/semiactive.md): an H2/LQG nominal controller on the
  // structure, i = max_current_A when (f_c - f) f > 0, else 0.
  double r_weight = 1e-2;            ///< weight on the force (in units of capacity), (0, 1e6]
  double noise_ratio = 25.0;         ///< ground-motion / sensor noise intensity (Dyke), (0, 1e6]
  double capacity_kN = 200.0;        ///< one damper's capacity (force unit of the cost), (0, 1e6]
};

/// Safety monitor (docs/safety.md): the clock stops the run, cleanly, when a limit is left.
/// Defaults are the paper's actuator ratings (556 kN, +/-152.4 mm stroke).
struct SafetyConfig {
  bool enabled = true;
  double stroke_mm = 152.4;        ///< |r|, |u|, |y| must stay within, (0, 10000]
  double force_kN = 556.0;         ///< |f| must stay within, (0, 1e6]
  double max_error_mm = 25.0;      ///< |r - y| must stay within, (0, 10000]
  /// Divergence: the peak |r - y| over consecutive windows of growth_window_s grows by at least
  /// growth_factor every window for growth_windows windows, above growth_floor_mm.
  double growth_window_s = 0.25;   ///< (0, 10]; at least one period of the oscillation to watch
  double growth_factor = 1.3;      ///< (1, 1000]
  int growth_windows = 4;          ///< [2, 1000]
  double growth_floor_mm = 0.5;    ///< (0, 10000]
};

/// Lockstep runtime knobs (docs/lockstep.md).
struct LockstepConfig {
  /// Re-request an incomplete step after this silence [ms], [5, 10000]; each further re-request
  /// of the same step waits twice as long, up to max(rerequest_ms, 1000 ms).
  double rerequest_ms = 100.0;
  /// Stop the run when one step has not completed for this long [s], [1, 3600] and at least
  /// 4 rerequest_ms: a participant that stopped answering. A loaded host only slows steps down.
  double stall_budget_s = 10.0;
  double handshake_timeout_s = 20; ///< abort if not every participant said hello, [0.1, 600]
};

/// Real-time paced mode (docs/realtime.md; `rths run --realtime` turns it on): the clock issues
/// step k at t0 + k dt of the wall clock (absolute deadlines) and counts the steps that complete
/// after their deadline t0 + (k+1) dt.
struct RealtimeConfig {
  bool enabled = false;                    ///< pace the clock to wall time
  /// Miss policy: 0 = continue and count; N > 0 = stop the run (exit 8) after N consecutive
  /// deadline misses, [0, 1e9].
  std::int64_t max_consecutive_misses = 0;
  bool sched_fifo = true;                  ///< try SCHED_FIFO for every participant process
  int priority = 80;                       ///< its SCHED_FIFO priority, [1, 99]
  bool lock_memory = true;                 ///< try mlockall(MCL_CURRENT | MCL_FUTURE)
};

/// Fault injection, off by default (docs/lockstep.md "Fault injection"): seeded random faults
/// on every message each participant receives, and one process fault.
struct FaultConfig {
  double drop = 0.0;           ///< fraction of received messages lost, [0, 0.5]
  double duplicate = 0.0;      ///< fraction delivered twice, [0, 0.5]
  double delay = 0.0;          ///< fraction delivered up to delay_ms late, [0, 0.5]
  double reorder = 0.0;        ///< fraction delivered after the next message, [0, 0.5]
  double delay_ms = 20.0;      ///< longest delay [ms], (0, 10000]
  std::int64_t seed = 1;       ///< [0, 2^53]
  /// udpm: each participant's UDP receive buffer [bytes] (LCM's recv_buf_size; 0 = the host's
  /// default), 0 or [1024, 2^27]: a small one loses messages in bursts.
  std::int64_t recv_buf_bytes = 0;
  /// [faults.process]: one participant stalls, throws, crashes, is killed or stopped at a step.
  std::string process_role;    ///< "" (none) or a participant: integrator, controller, plant, semiactive, logger
  std::string process_kind;    ///< stall | throw | crash | kill | stop (crash, kill, stop: udpm only)
  std::int64_t process_at_step = 0;  ///< [0, steps)
  double process_stop_s = 0.0; ///< "stop": continue after this many seconds, 0 = never, [0, 3600]
  bool any_network() const { return drop > 0 || duplicate > 0 || delay > 0 || reorder > 0; }
};

struct RunConfig {
  std::string name = "run";
  double dt_s = 0.0005;       ///< lockstep step [s], [1e-5, 0.01]
  double duration_s = 20.0;   ///< simulated time [s], (0, 36000]
};

struct Scenario {
  std::string path;     ///< file it came from ("" if parsed from text)
  std::string sha256;   ///< hex SHA-256 of the file's bytes (the handshake compares these)
  RunConfig run;
  StructureConfig structure;
  ControllerConfig controller;
  PlantConfig plant;
  SemiactiveConfig semiactive;
  LockstepConfig lockstep;
  RealtimeConfig realtime;
  SafetyConfig safety;
  FaultConfig faults;

  /// Number of lockstep steps: round(duration_s / dt_s).
  std::int64_t steps() const;
};

/// Reads, hashes, parses and validates a scenario file. Throws rths::Error.
Scenario LoadScenario(const std::string& path);
/// Parses and validates TOML text; `path` is used in messages and to resolve relative files.
Scenario ParseScenario(std::string_view toml_text, const std::string& path);
/// Checks every range and cross-field limit (the second half of ParseScenario); for scenarios
/// built or modified in code. Messages name s.path. Throws rths::Error.
void ValidateScenario(const Scenario& s);
/// The scenario as TOML text with every key written out (ParseScenario of it gives back the same
/// scenario). Used to store programmatic variants as files, so every run has a real file and hash.
std::string ToToml(const Scenario& s);
/// Hex SHA-256 of a byte string.
std::string Sha256Hex(std::string_view bytes);

}  // namespace rths::scenario
