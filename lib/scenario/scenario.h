#pragma once
/// @file Scenario: a TOML file parsed once, at the edge, into plain structs with defaults; every
/// file it names (structure, reference structure, signal records) is read once there too.
///
/// Units follow docs/units.md: paper units (mm, kN, s, A) everywhere; the only other edge
/// unit is mass, given in kg in the file and converted to kN s^2/mm by the components.
/// Every field has a default; LoadScenario() rejects unknown keys, wrong types and
/// out-of-range values with an rths::Error naming the file, the key and the allowed range.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "control/clipped_optimal.h"
#include "control/controller_config.h"
#include "control/marths_config.h"
#include "lockstep/config.h"
#include "lockstep/faults.h"
#include "lockstep/realtime.h"
#include "models/rig.h"
#include "models/structure_file.h"
#include "safety/monitor.h"

namespace rths::scenario {

/// The run itself ([run]).
struct RunConfig {
  std::string name = "run";
  double dt_s = 0.0005;       ///< lockstep step [s], [1e-5, 0.01]
  double duration_s = 20.0;   ///< simulated time [s], (0, 36000]
  /// signals.csv gets a row every csv_every steps (1: every step; 10: every 10th; 0: no
  /// signals.csv). log.lcm always holds every step (`rths export` makes a full CSV or .mat of it).
  int csv_every = 1;
  bool operator==(const RunConfig&) const = default;
};

/// Everything a run needs, gathered from one file: each table's struct lives beside the component
/// that uses it (models, control, safety, lockstep); this library only reads, validates and
/// writes them. Config is parsed and every file it names is read once, at the edge: the loader
/// fills the data members (models::StructureConfig::matrices and reference,
/// signal::SignalSpec::record) beside the paths, which stay as the file names them (ToToml writes
/// them; `sha256` is the hash of the scenario text). Components (participants, the supervisor's
/// estimates) take the data, never paths or environment variables; each process loads once.
struct Scenario {
  std::string path;     ///< file it came from ("" if parsed from text)
  std::string sha256;   ///< hex SHA-256 of the file's bytes (the handshake compares these)
  RunConfig run;
  models::StructureConfig structure;
  control::ControllerConfig controller;
  models::PlantConfig plant;
  control::SemiactiveConfig semiactive;
  lockstep::LockstepConfig lockstep;
  lockstep::RealtimeConfig realtime;
  safety::SafetyConfig safety;
  lockstep::FaultConfig faults;
  /// The maRTHS benchmark's two-actuator loop instead of the tables above (docs/marths.md).
  control::MarthsConfig marths;

  /// Number of lockstep steps: round(duration_s / dt_s).
  std::int64_t steps() const;
  bool operator==(const Scenario&) const = default;
};

/// Reads, hashes, parses and validates a scenario file, and reads every file it names
/// (ReadReferencedFiles). Throws rths::Error.
Scenario LoadScenario(const std::string& path);
/// Parses and validates TOML text, then reads the files it names (ReadReferencedFiles) and makes
/// their paths absolute; `path` is used in messages and to resolve relative files.
Scenario ParseScenario(std::string_view toml_text, const std::string& path);
/// Checks every range and cross-field limit (the second half of ParseScenario); for scenarios
/// built or modified in code. Messages name s.path. Throws rths::Error.
void ValidateScenario(const Scenario& s);
/// Reads every file `s` names, once, into its data members: structure.matrices (structure.file, for
/// mode "rths" and kind "file"), structure.reference (structure.reference_file), and the rows of
/// structure.ground and structure.desired (kind "file"); the others are cleared. Relative paths are
/// taken relative to s->path's folder. ParseScenario calls it; a scenario changed in code calls it
/// after changing a path. Throws rths::Error: a structure or signal file's own error (naming the file
/// and line), "<scenario>: structure.reference_file" (unreadable, or other DOFs than
/// structure.file), "<scenario>: structure.actuator_dof" (beyond the structure's DOFs).
void ReadReferencedFiles(Scenario* s);
/// The scenario as TOML text with every key written out (ParseScenario of it gives back the same
/// scenario). Used to store programmatic variants as files, so every run has a real file and hash.
std::string ToToml(const Scenario& s);
/// Applies command-line overrides to scenario TOML text (`--set KEY=VALUE`, issue 13): KEY is a
/// dotted key ("run.duration_s", "controller.kind", "plant.damper.c0a"), created if absent (tables
/// too); VALUE is a TOML value ("5", "2.5e-4", "true", "[1, 2]", "\"ff\""), and a bare word that
/// is not one ("ff_lqg") is taken as a string. Returns the text with the keys replaced (comments
/// are not kept). Throws rths::Error naming the --set argument when it has no '=', an empty key,
/// or a key that runs through a value that is not a table. Ranges and unknown keys are checked
/// afterwards, by ParseScenario, exactly as for the file.
std::string ApplyOverrides(std::string_view toml_text, const std::vector<std::string>& sets,
                           const std::string& path);
/// LoadScenario(path) with `sets` applied (ApplyOverrides) before parsing and validation; the
/// hash is that of the overridden text. Without sets: LoadScenario(path). Errors of the
/// validation that concern a set key say so ("(set by --set KEY=VALUE)").
Scenario LoadScenario(const std::string& path, const std::vector<std::string>& sets);
/// A scenario with `sets` applied: ToToml(s), ApplyOverrides, ParseScenario (paths resolved as
/// in s.path). For scenarios built in code (the reproductions' runs).
Scenario WithOverrides(const Scenario& s, const std::vector<std::string>& sets);
/// Hex SHA-256 of a byte string.
std::string Sha256Hex(std::string_view bytes);

}  // namespace rths::scenario
