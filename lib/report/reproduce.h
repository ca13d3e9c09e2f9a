#pragma once
/// @file The reproductions of the paper's figures and tables (experiments.md), as library
/// functions: tools/reproduce.cpp (`rths reproduce NAME`) parses options and calls these, and
/// tests/reproduce_test.cpp calls them directly.
///
/// Every function writes into opts.out_dir (created; refused if it exists and is not empty):
/// CSV tables (RFC 4180, report/csv.h), Markdown where there is a table, PNG figures made with
/// gnuplot (report/plot.h) and, for lockstep studies, every run's folder under out_dir/runs/.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "report/batch.h"
#include "scenario/scenario.h"

namespace rths::report {

struct ReproduceOptions {
  std::filesystem::path out_dir;          ///< where the files go
  bool quick = false;                     ///< shorter records (tests); full: experiments.md lengths
  std::string plant = "physical";         ///< "physical" (models.md section 5) | "linear" (Eqs. 28-30)
  int jobs = 2;                           ///< lockstep groups run at the same time (threads)
  std::function<void(std::string_view)> log;  ///< progress lines ("" = silent)
  std::string gnuplot = "gnuplot";        ///< plotting program
};

/// Creates `dir`, or accepts it if it exists and is empty; throws rths::Error if it holds
/// anything (a reproduction never overwrites an earlier one).
void PrepareOutDir(const std::filesystem::path& dir);

/// Throws rths::Error with a clear message unless `plant` is "linear" or "physical", and, for
/// "physical", unless this build's plant really runs the physics-based actuator (it runs a
/// 0.1 s probe on both plants in a scratch folder under `scratch_parent` and compares).
void RequirePlant(const std::string& plant, const std::filesystem::path& scratch_parent);

// --- Fig. 5 (E6): the MR damper under a 25.4 mm, 1 Hz sine ---------------------------------

struct Fig5Result {
  std::vector<double> current_A;        ///< 0, 0.5, ..., 2.5
  std::vector<double> paper_peak_kN;    ///< the reference of experiments.md E6
  std::vector<double> ours_peak_kN;     ///< max |F| over the 2nd and 3rd cycles
};
/// The E6 reference peaks [kN] at 0, 0.5, 1.0, 1.5, 2.0, 2.5 A.
const std::vector<double>& Fig5ReferencePeaksKn();
/// Writes fig5_peaks.csv (current_A,paper_peak_kN,ours_peak_kN), fig5_loops.csv (t, x, v, F per
/// current) and fig5.png (force-time, force-displacement, force-velocity side by side).
Fig5Result ReproduceFig5(const ReproduceOptions& opts);

// --- Table 2 (E3): time-domain tracking --------------------------------------------------

/// One controller row of Table 2 (both bands).
struct Table2Controller {
  std::string condition;           ///< "0.0A" | "2.5A" | "pulse"
  std::string name;                ///< the paper's short name, e.g. "G_FF,0.0A + LP"
  double paper_pct_5 = 0.0;        ///< Table 2, 0-5 Hz BLWN
  double paper_pct_15 = 0.0;       ///< Table 2, 0-15 Hz BLWN
  std::string paper_text_5, paper_text_15;  ///< as printed ("16.0", "0.942")
  scenario::ControllerConfig controller;    ///< kind and design
};
/// The 18 controller rows of Table 2, in the paper's order.
std::vector<Table2Controller> Table2Controllers();

/// The scenario of one Table 2 run: predefined BLWN (models.md section 9; 0-5 Hz RMS 2.78 mm
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

/// One of the paper's claims (experiments.md E3) checked on our table.
struct Claim {
  std::string text;
  bool holds = false;
  std::string detail;              ///< the numbers behind it
};

struct Table2Result {
  std::vector<Table2Row> rows;     ///< 36: condition x controller x band, in the paper's order
  std::vector<Claim> claims;
  double wall_s = 0.0;
};
/// Runs the 36 lockstep runs (60 s records; --quick: 6 s, and 20 s for the "None" rows so that
/// their check against the paper means something) and writes table2.csv
/// (condition,controller,band_hz,paper_pct,ours_pct), table2.md and runs/<row>/.
/// Throws rths::Error before running anything if a controller or the plant is not available.
Table2Result ReproduceTable2(const ReproduceOptions& opts);
/// The claims of E3 on a finished table (rows as ReproduceTable2 returns them).
std::vector<Claim> CheckTable2Claims(const std::vector<Table2Row>& rows);

}  // namespace rths::report
