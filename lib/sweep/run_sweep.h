#pragma once
/// @file The local executor of a sweep (`rths sweep SPEC`, issue 28): the SPEC's runs (or one of
/// them, or those a previous attempt left undone), `jobs` at a time on this machine
/// (studies::RunBatch: each run a memq group in this process), one row per run written as soon as
/// the run ends (an interrupted sweep keeps every finished run's row), and the table of every row.
///
/// Folder layout (DIR): DIR/runs/<i>/ (scenario.toml, summary.json; log.lcm and signals.csv only
/// with keep_logs), DIR/rows/<i>.json (the run's row, written once the run has ended, whatever its
/// status), DIR/table.csv and the other results of sweep/table.h (every row present, by index).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "sweep/spec.h"

namespace rths::sweep {

struct SweepOptions {
  std::filesystem::path out;          ///< DIR (created)
  int jobs = 1;                       ///< runs at a time, >= 1
  std::optional<std::int64_t> only;   ///< run only this index (re-made alone, bit for bit)
  /// Run only the indices i with i % chunks == chunk (one task of a job array), 0 <= chunk < chunks.
  std::int64_t chunk = 0, chunks = 1;
  bool resume = false;                ///< skip runs whose row is already in DIR/rows
  bool keep_logs = false;             ///< keep each run's log.lcm and signals.csv
  bool write_table = true;            ///< write the table at the end (not in an array task: the collector does)
  ProgressLine* progress = nullptr;   ///< progress with ETA (optional)
};

struct SweepOutcome {
  std::int64_t ran = 0, skipped = 0, failed = 0;  ///< this call's runs; rows already there; this call's rows not "completed"
  std::vector<std::int64_t> kept;  ///< with resume: the indices skipped (their rows kept), ascending
  /// What model the model-based controllers of this call's runs were designed on, each distinct
  /// line once (ident::ResolveDesignModel: a benchmark scenario's controller designs on the
  /// plant's Gp; "warning: ..." where the design is on another plant's model).
  std::vector<std::string> design_notes;
  /// With the table written: its rows, and those not "completed" (earlier attempts' included).
  std::int64_t rows = 0, not_completed = 0;
  std::vector<std::string> absent_fields;         ///< recorded fields no completed row has (AbsentFields)
  std::filesystem::path table;                    ///< DIR/table.csv
};

/// Runs the sweep's runs as `o` says and writes their rows and the table. A run that cannot be
/// built (a drawn value out of range) or fails is a row with its status, never an exception; an
/// unwritable DIR throws rths::Error.
SweepOutcome RunSweep(const Spec& spec, const SweepOptions& o);

/// What WriteTable wrote: table.csv's path, its rows, those not "completed", and the recorded
/// fields no completed row has (AbsentFields).
struct WrittenTable {
  std::filesystem::path csv;
  std::int64_t rows = 0, not_completed = 0;
  std::vector<std::string> absent_fields;
};

/// Writes DIR/table.csv, table.h5, summary.csv and plots/ (sweep/table.h) from every row present
/// in DIR/rows, read once. Throws rths::Error if the tables cannot be written (a plot that fails
/// leaves its message in plots/FAILED.txt instead).
WrittenTable WriteTable(const Spec& spec, const std::filesystem::path& out);

}  // namespace rths::sweep
