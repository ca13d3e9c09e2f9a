#pragma once
/// @file Table 2 (docs/experiments.md E3): tracking of predefined BLWN displacement histories, 36
/// lockstep runs (3 conditions x 6 controllers x 2 bands), Eq. 31 on the logged r_k, y_k; with
/// --extended, the extended table's runs in the same batch (studies/table2_extended.h).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scenario/scenario.h"
#include "studies/pi_lead.h"
#include "studies/study.h"
#include "studies/table2_extended.h"

namespace rths::studies {

/// One controller row of Table 2 (both bands).
struct Table2Controller {
  std::string condition;           ///< "0.0A" | "2.5A" | "pulse"
  std::string name;                ///< the paper's short name, e.g. "G_FF,0.0A + LP"
  double paper_pct_5 = 0.0;        ///< Table 2, 0-5 Hz BLWN
  double paper_pct_15 = 0.0;       ///< Table 2, 0-15 Hz BLWN
  std::string paper_text_5, paper_text_15;  ///< as printed ("16.0", "0.942")
  control::ControllerConfig controller;    ///< kind and design
};
/// The 18 controller rows of Table 2, in the paper's order.
std::vector<Table2Controller> Table2Controllers();

/// The scenario of one Table 2 run: predefined BLWN (docs/models.md section 9; 0-5 Hz RMS 2.78 mm
/// or 0-15 Hz RMS 0.595 mm, fixed seed), the damper attached, the condition's current and the
/// plant ("linear" uses Eq. 28 / 29 / 30 for 0.0A / 2.5A / pulse).
scenario::Scenario Table2Scenario(const Table2Controller& row, double band_hz, const std::string& plant,
                                  double duration_s);

struct Table2Row {
  std::string condition, controller, band;  ///< band "0-5" | "0-15"
  double paper_pct = 0.0;
  std::string paper_text;
  double ours_pct = 0.0;
  double duration_s = 0.0;
  std::filesystem::path run_dir;
};

struct Table2Result {
  std::vector<Table2Row> rows;     ///< 36: condition x controller x band, in the paper's order
  std::vector<Claim> claims;
  /// --extended: 36 rows, condition x band x controller, in Table2ExtendedControllers' order.
  std::vector<Table2ExtendedRow> extended;
  std::optional<PiLeadDesign> pi_lead;  ///< --extended: the design on Eq. 30
  double wall_s = 0.0;
};
/// Runs the 36 lockstep runs (60 s records; --quick: 6 s, and 20 s for the "None" rows so that
/// their check against the paper means something) and writes table2.csv
/// (condition,controller,band_hz,paper_pct,ours_pct), table2.md and runs/<row>/.
/// With opts.extended, in the same batch, the extended table's 18 new runs (ats, ambc, pi_lead per
/// condition and band; none, ff and ff_lqg are the Table 2 rows' runs) and table2_extended.csv,
/// table2_extended.md, table2_extended.png (if gnuplot is there); a new run the safety monitor
/// stops is a row with its reason, not an error (a Table 2 row that fails still throws).
/// Throws rths::Error before running anything if a controller or the plant is not available.
Table2Result ReproduceTable2(const ReproduceOptions& opts);
/// The claims of E3 on a finished table (rows as ReproduceTable2 returns them).
std::vector<Claim> CheckTable2Claims(const std::vector<Table2Row>& rows);

}  // namespace rths::studies
