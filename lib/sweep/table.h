#pragma once
/// @file A sweep's results (issue 28), made from its rows (DIR/rows/<i>.json) once its runs have
/// ended, by either executor:
///
///   DIR/table.csv     one line per row, by index: the columns of TableColumns; doubles as the
///                     shortest text that reads back bit for bit
///   DIR/table.h5      the same table in HDF5 (Debian's libhdf5): group /runs, one 1-D dataset per
///                     column, named as the column, in the order of /runs's attribute `columns`:
///                     float64 for numbers (NaN where a row has none), int64 for integers present in
///                     every row, variable-length UTF-8 strings otherwise. MATLAB:
///                     h5read('table.h5', '/runs/tracking_nrmse_pct'); Python (h5py, pandas):
///                     pd.DataFrame({c: f['runs'][c][()] for c in f['runs'].attrs['columns']})
///                     (strings: f['runs'][c].asstr()[()]).
///   DIR/summary.csv   per group (a case and a grid combination: the runs that differ only in their
///                     draws) and recorded numeric field: runs, failures (rows not "completed"), n
///                     (completed rows with a finite value), mean, sample std, min, max
///   DIR/plots/<field>.png  each recorded numeric field against each axis (case, grid keys,
///                     drawn keys), a panel per axis, completed runs only, a curve (colour) per
///                     level of the other factor (the first other case or grid axis): against a
///                     case or grid key a line through the mean of each point's runs (the runs as
///                     open points when there are draws), against a drawn key the runs as points;
///                     5 % of the plot area between the data and the frame (gnuplot; skipped,
///                     with a note, where gnuplot is not installed)
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep/spec.h"

namespace rths::sweep {

/// The rows present, as cells of TableColumns(spec), in index order.
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<nlohmann::json>> rows;  ///< null: no value
  std::vector<std::int64_t> group;                ///< per row: case x combination index (the draws' group)
};

/// The table's columns: index, status, scenario_sha256, case (with [cases] files only: the case's
/// file name, or its path relative to the SPEC's folder where two cases share a file name), each grid key, each drawn key (DrawColumns), each recorded field (named "summary.<field>" where its name is already a column's, e.g. summary.json's "status").
std::vector<std::string> TableColumns(const Spec& spec);

/// DIR/rows/<i>.json: run i's row.
std::filesystem::path RowFile(const std::filesystem::path& out, std::int64_t i);

/// A JSON file (a row, a summary.json); null if absent or malformed.
nlohmann::json ReadJsonFile(const std::filesystem::path& file);

/// Reads DIR/rows/<i>.json for every index of the sweep (absent rows are left out).
Table ReadTable(const Spec& spec, const std::filesystem::path& out);

/// The recorded fields no completed row has a value for: not in summary.json (a misspelt name?).
std::vector<std::string> AbsentFields(const Spec& spec, const Table& t);

/// DIR/table.csv. Throws rths::Error if it cannot be written.
void WriteCsv(const Table& t, const std::filesystem::path& file);
/// DIR/table.h5 (the layout above). Throws rths::Error if HDF5 cannot write it.
void WriteHdf5(const Spec& spec, const Table& t, const std::filesystem::path& file);
/// DIR/summary.csv (the layout above).
void WriteGroupSummary(const Spec& spec, const Table& t, const std::filesystem::path& file);
/// DIR/plots/<field>.png; returns the PNGs written (none without a numeric field or gnuplot).
std::vector<std::filesystem::path> WritePlots(const Spec& spec, const Table& t, const std::filesystem::path& dir);

}  // namespace rths::sweep
