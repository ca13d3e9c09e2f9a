#pragma once
/// @file The extended Table 2 (`rths reproduce table2 --extended`, issue 25; docs/reproduce_table2.md):
/// beside the paper's proposed controllers and none, the field's adaptive compensators (ats, ambc)
/// and pi_lead (studies/pi_lead.h). ReproduceTable2 (studies/table2.h) runs its rows in the same
/// batch as Table 2's, then measures them and writes their files with what is declared here.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "control/controller_config.h"
#include "studies/pi_lead.h"
#include "studies/study.h"

namespace rths::studies {

/// Table2Scenario's run.dt_s (2 kHz): the step pi_lead is designed at.
inline constexpr double kTable2DtS = 0.0005;

/// One row of the extended table: a condition, band and controller.
struct Table2ExtendedRow {
  std::string condition, band;       ///< "0.0A" | "2.5A" | "pulse"; "0-5" | "0-15"
  std::string controller;            ///< none, ff, ff_lqg, ats, ambc, pi_lead
  std::string table2_row;            ///< the Table 2 row whose run it is ("G_FF,2.5A"), or ""
  double ours_pct = 0.0;             ///< Eq. 31 over every logged step (NaN: no log)
  double second_half_pct = 0.0;      ///< Eq. 31 over the second half of the logged steps
  double peak_error_mm = 0.0;        ///< max |r_k - y_k|
  std::int64_t steps = 0, steps_planned = 0;
  std::string stopped = "no";        ///< "no", or why the run stopped (the safety monitor's reason)
  std::vector<double> final_coefficients;  ///< ats, ambc: a0 [-], a1 [s], a2 [s^2] (, a3 [s^3]) at the last step
  double adapt_start_s = -1.0;       ///< ats, ambc: first time the coefficients left their start (-1: never)
  double duration_s = 0.0;
  std::filesystem::path run_dir;
};

/// One controller of the extended table, for one condition.
struct Table2ExtendedController {
  std::string condition;             ///< "0.0A" | "2.5A" | "pulse"
  std::string name;                  ///< none, ff, ff_lqg, ats, ambc, pi_lead
  std::string table2_row;            ///< none, ff, ff_lqg: the Table 2 row whose run it is; else ""
  std::string design;                ///< one line: how it is set up
  control::ControllerConfig controller;
};
/// The extended table's controllers for one condition, in order: none, ff, ff_lqg (the condition's
/// Table 2 rows "None", its G_FF row, "G_FF,avgA + LQG"), ats (AtsConfig's defaults), ambc
/// (start = "model" on the design model of the condition's G_FF row, other keys default),
/// pi_lead (`pi_lead.controller`).
std::vector<Table2ExtendedController> Table2ExtendedControllers(const std::string& condition,
                                                                const PiLeadDesign& pi_lead);

/// Fills the measured fields of `rows` (ours_pct, second_half_pct, peak_error_mm, steps,
/// final_coefficients, adapt_start_s) from each row's log.lcm (`jobs` logs read at a time); a row
/// without a log gets NaN numbers and keeps its `stopped`.
void MeasureExtendedRows(std::vector<Table2ExtendedRow>* rows, int jobs);

/// Writes table2_extended.csv, table2_extended.md and (if gnuplot is there) table2_extended.png.
void WriteTable2Extended(const ReproduceOptions& opts, const std::vector<Table2ExtendedRow>& rows,
                         const PiLeadDesign& pi_lead);

}  // namespace rths::studies
