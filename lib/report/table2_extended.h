#pragma once
/// @file The extended Table 2 (`rths reproduce table2 --extended`, docs/reproduce_table2.md): what
/// ReproduceTable2 (table2.cpp) calls to measure the extended rows' runs and write their files.
/// The design rule of `pi_lead` and the controllers are declared in report/reproduce.h.
#include <vector>

#include "report/batch.h"
#include "report/reproduce.h"

namespace rths::report {

/// Table2Scenario's run.dt_s (2 kHz): the step pi_lead is designed at.
inline constexpr double kTable2DtS = 0.0005;

/// Fills the measured fields of `rows` (ours_pct, second_half_pct, peak_error_mm, steps,
/// final_coefficients, adapt_start_s) from each row's log.lcm (`jobs` logs read at a time); a row
/// without a log gets NaN numbers and keeps its `stopped`.
void MeasureExtendedRows(std::vector<Table2ExtendedRow>* rows, int jobs);

/// Writes table2_extended.csv, table2_extended.md and (if gnuplot is there) table2_extended.png.
void WriteTable2Extended(const ReproduceOptions& opts, const std::vector<Table2ExtendedRow>& rows,
                         const PiLeadDesign& pi_lead);

}  // namespace rths::report
