#pragma once
/// @file A run's signals (io/run_signals.h) as a MATLAB file through matio (Debian's libmatio),
/// and as a CSV table. Layout of the .mat file (docs/export.md): one struct variable `rths` with
///   rths.signals.<name>       one double column vector per signal (n x 1), in RunSignals order
///   rths.units.<name>         its unit ("mm", "kN", ...; "" for k)
///   rths.descriptions.<name>  one line saying what it is
///   rths.names                the signal names in column order, comma-separated ("k,t_s,r_mm,...";
///                             strsplit(rths.names, ',') gives a cell array)
///   rths.meta                 run_id (int64), dt_s, steps, planned_steps, complete (0/1),
///                             status, scenario (scenario.toml text), scenario_sha256,
///                             source_log, rths_version, matio_version
/// so that `d = load('export.mat'); plot(d.rths.signals.t_s, d.rths.signals.y_mm)` works.
#include <cstdint>
#include <filesystem>
#include <string>

#include "io/run_signals.h"

namespace rths::io {

/// MATLAB file format: v5 (MATLAB 5 to today, Octave, SciPy's loadmat) or v7.3 (HDF5; h5py).
enum class MatVersion { kV5, kV73 };

/// What the file says about its run, beside the signals (rths.meta).
struct ExportMeta {
  std::int64_t run_id = 0;
  std::int64_t planned_steps = 0;  ///< the handshake's n_steps (0 if unknown)
  bool complete = false;           ///< the log is whole (the run finished)
  std::string status;              ///< "finished" or RunLog::TruncationReason()
  std::string scenario_toml;       ///< the exact text of the run's scenario.toml
  std::string scenario_sha256;     ///< as in the handshake ("" if unknown)
  std::string source_log;          ///< path of the log.lcm the signals were decoded from
};

/// "rths <version>" of this build.
std::string RthsVersion();
/// The matio library's version ("1.5.23").
std::string MatioVersion();

/// Writes `signals` and `meta` to `path` in the layout above. A new or regular file is written
/// beside `path` under a temporary name and renamed into place, so a failure never leaves a
/// half-written file (an existing file at `path` is replaced); a device, FIFO or symbolic link
/// at `path` is written in place. Throws rths::Error naming `path` if it cannot be
/// written (with the system's reason), if this matio cannot write v7.3 (built without HDF5), or
/// if a signal name is not a valid MATLAB field name (letters, digits, '_', starting with a
/// letter, at most 63 characters).
void WriteMat(const std::filesystem::path& path, const RunSignals& signals, const ExportMeta& meta,
              MatVersion version);

/// Writes `signals` as RFC 4180 CSV (io/csv.h): a header of the signal names (units in the names:
/// y_mm, f_kN, t_s; k is the step index), then one row per step, every value as the shortest text that
/// reads back as the same double (exact round trip). Same temporary-name-and-rename rule and errors as WriteMat.
void WriteSignalsCsv(const std::filesystem::path& path, const RunSignals& signals);

}  // namespace rths::io
