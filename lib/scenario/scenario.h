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
};

/// Numerical substructure (procs/integrator).
struct StructureConfig {
  std::string mode = "rths";  ///< "rths" (central difference, Eqs. 1-3) | "predefined" (r from a history)
  // mode = "rths": an SDOF structure.
  double mass_kg = 20000.0;          ///< (0, 1e9]
  double frequency_hz = 5.0;         ///< natural frequency (0, 1/(pi dt)) -- central-difference limit omega dt < 2
  double damping_ratio = 0.02;       ///< [0, 1)
  double specimen_count = 1.0;       ///< measured force multiplier (18 dampers act as one) (0, 1000]
  SignalSpec ground{};               ///< ground acceleration [mm/s^2]
  // mode = "predefined": the desired displacement itself [mm].
  SignalSpec desired{"blwn", 5.0, 2.78, 1, 2.0, "", 0.0, 1.0};
  /// How the integrator gets r', r'', r''' in predefined mode: "extrapolated" (Eqs. 20-22, the
  /// causal RTHS path) | "central" (offline, non-causal central differences of the known record).
  std::string derivatives = "extrapolated";
};

/// Outer-loop tracking controller (procs/controller).
struct ControllerConfig {
  std::string kind = "ff";     ///< "none" (u = r) | "ff" (model inverse, Eqs. 16-22)
  ServoModel3 model{};         ///< design model for "ff"
  /// models.md section 2: evaluate the feedforward half a step ahead to cancel the ZOH's
  /// half-sample lag in simulation. false = the paper's Eq. 19.
  bool half_step_ahead = false;
};

/// "Physical" substructure and loading system (procs/plant).
struct PlantConfig {
  ServoModel3 actuator{};              ///< linear servohydraulic model, ZOH-discretised
  std::string specimen = "mr_damper";  ///< "mr_damper" (Eqs. 32-39, Table 3) | "none"
  double noise_y_mm_rms = 0.0;         ///< Gaussian sensor noise on y [mm], [0, 10]
  double noise_f_kN_rms = 0.0;         ///< Gaussian sensor noise on f [kN], [0, 100]
  std::uint64_t noise_seed = 7;
  double cvode_rtol = 1e-8;            ///< CVODE relative tolerance, (0, 1e-2]
};

/// Semiactive current (procs/semiactive). For now a constant current; clipped-optimal later.
struct SemiactiveConfig {
  std::string mode = "passive_off";  ///< "passive_off" (0 A) | "passive_on" (max_current_A) | "constant"
  double current_A = 0.0;            ///< for "constant": [0, max_current_A]
  double max_current_A = 2.5;        ///< (0, 5]
};

/// Lockstep runtime knobs (docs/lockstep.md).
struct LockstepConfig {
  double timeout_ms = 250.0;       ///< re-request step k after this silence [ms], [1, 60000]
  int max_attempts = 8;            ///< abort after this many requests of one step, [1, 1000]
  double handshake_timeout_s = 20; ///< abort if not every participant said hello, [0.1, 600]
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
/// Hex SHA-256 of a byte string.
std::string Sha256Hex(std::string_view bytes);

}  // namespace rths::scenario
