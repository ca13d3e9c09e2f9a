#pragma once
/// @file Rig records in the files labs have (docs/rig_record.md "Other formats"): any CSV with
/// named columns and a MATLAB .mat file, mapped onto a rig record by a column map
/// (`--columns` of `rths identify` and `rths diagnose`), so that a lab never writes a converter.
///
/// Column map: comma-separated entries ROLE=SOURCE[*SCALE][:UNIT]
///     ROLE    t (time), u (command), y (measured displacement), f (force), i (damper current),
///             v (damper voltage), r (desired displacement); or dt=STEP_S for a file without a
///             time column; or i=VALUE[:UNIT] (v=VALUE[:UNIT]) for a file without a current (voltage)
///             column, run at that constant command (a lab's damper tests at fixed currents)
///     SOURCE  a CSV column's name (as in its header line, quotes removed), or a .mat variable:
///             NAME (a vector), NAME.FIELD (a struct's field), NAME(:,K) (column K of a matrix, 1-based)
///     SCALE   a factor the source is multiplied by first (e.g. a DAQ's volts to engineering units)
///     UNIT    the unit of SCALE x SOURCE, converted to the record's: time s, ms; displacement
///             mm, cm, m, in; force kN, N, MN, lbf, kip; current A, mA; voltage V, mV
/// e.g. `t=t,y=D:cm,f=F:N,v=Y:V` or `t=Time:ms,u=CH2*10:mm,y=CH0*10:mm,f=CH1*9.80665:kN`.
/// Required: y and f, and t or dt. Without u, u = y (a damper test: the command is not in the
/// file; a warning says so); without i and v, i = 0 A (a warning says so).
///
/// Time: dt is the time column's mean step (t_last - t_0) / (n - 1); a column that increases and
/// lies within half a step of t_0 + k dt everywhere (no row missing or extra; a column rounded
/// coarser than its step passes, with a warning above 1 % of a step) becomes t_0 + k dt; any
/// other is checked as ValidateRigRecord checks (gaps, non-uniform steps). With dt= the time axis
/// is k dt.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/rig_record.h"

namespace rths::io {

/// One entry of a column map.
struct ColumnSource {
  char role = 0;          ///< 't', 'u', 'y', 'f', 'i', 'v', 'r'
  std::string source;     ///< column or variable name (file comment)
  double scale = 1.0;     ///< the SCALE factor
  std::string unit;       ///< as written ("" = the record's unit)
  double to_record = 1.0; ///< SCALE x the unit's factor to the record's unit (mm, kN, s, A, V)
};

/// A parsed column map (file comment).
struct ColumnMap {
  std::vector<ColumnSource> columns;
  std::optional<double> dt_s;  ///< dt=STEP_S [s], for a file without a time column
  /// i=VALUE [A] (v=VALUE [V]): a constant damper command for a file without its column.
  std::optional<double> current_A, voltage_V;

  /// The entry for `role`, or nullptr.
  const ColumnSource* Find(char role) const;
  /// The map as text, for a record's metadata.
  std::string Describe() const;
};

/// Parses a column map (file comment). Throws rths::Error(where = `where`, e.g. "--columns")
/// naming the bad entry and what is allowed: an unknown role or unit, a role twice, a bad
/// SCALE or dt, no y or f, neither t nor dt (or both).
ColumnMap ParseColumnMap(std::string_view text, const std::string& where = "--columns");

/// A record from the map's columns, already read (`values[j]` for map.columns[j], in the source's
/// units): applies the factors, the defaults for u and i, the time axis; then ValidateRigRecord.
/// Throws rths::Error(path) if the lengths differ.
RigRecord RecordFromColumns(const ColumnMap& map, const std::string& path, std::vector<std::vector<double>> values);

/// Reads a CSV file with a header line of column names (the first line that is not empty or a
/// '#' comment; separated by ',', ';' or tabs, whichever the header uses; names may be quoted;
/// columns the map does not name are ignored, even if empty). Throws rths::Error("path:line")
/// for a missing column (naming the file's columns), a mapped field that is not a finite number,
/// a row too short, and whatever ValidateRigRecord finds.
RigRecord ReadColumnsCsv(const std::string& path, const ColumnMap& map);

/// The column names of a CSV file's header line (as ReadColumnsCsv finds it); empty if none.
std::vector<std::string> CsvColumnNames(const std::string& path);

/// True if the file starts with a MATLAB .mat signature ("MATLAB 5.0 MAT-file" or an HDF5 v7.3
/// file whose 512-byte user block says so).
bool IsMatFile(const std::string& path);

/// Reads a .mat record: with a map, the map's variables; without, the variables named as the
/// CSV rig record's columns (t_s, u_mm, y_mm, f_kN, i_A or v_V, r_mm; a scalar dt_s is used if
/// t_s is absent). Throws rths::Error(path) naming a missing variable (and the file's variables)
/// or one that is not a real numeric vector.
RigRecord ReadMatRecord(const std::string& path, const ColumnMap* map);

/// Names for a message: comma-separated, empty ones skipped; "(none)" if none is left.
std::string JoinNames(const std::vector<std::string>& names);

/// The variable names of a .mat file (for messages).
std::vector<std::string> MatVariableNames(const std::string& path);

/// Any record a tool takes. Our own formats as they are, map or not: an LCM log, a CSV rig record,
/// a UTFSM DAQ export (ReadRecordOrUtfsm, utfsm.h), so that one map serves a mix of a lab's files
/// and ours. Then a .mat file (through the map, or in the rig-record names without one); with a
/// map, a CSV with named columns; without one, a UTFSM damper file (rows of numbers). A file that
/// is none of these is refused with the option that reads it (--columns, naming its columns).
RigRecord ReadAnyRecord(const std::string& path, const ColumnMap* map, TimeAxis time = TimeAxis::kColumn);

}  // namespace rths::io
