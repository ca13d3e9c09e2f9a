#pragma once
/// @file The reproductions of the paper's figures and tables (docs/experiments.md), as library
/// functions: tools/reproduce.cpp (`rths reproduce NAME`) parses options and calls these, and
/// tests/reproduce_test.cpp calls them directly.
///
/// Every function writes into opts.out_dir (created; refused if it exists and is not empty):
/// CSV tables (RFC 4180, io/csv.h), Markdown where there is a table, PNG figures made with
/// gnuplot (io/plot.h) and, for lockstep studies, every run's folder under out_dir/runs/.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "ident/fit.h"
#include "core/progress.h"
#include "report/batch.h"
#include "scenario/scenario.h"
#include "signal/spectral.h"

namespace rths::report {

struct ReproduceOptions {
  std::filesystem::path out_dir;          ///< where the files go
  bool quick = false;                     ///< shorter records (tests); full: docs/experiments.md lengths
  std::string plant = "physical";         ///< "physical" (docs/models.md section 5) | "linear" (Eqs. 28-30)
  int jobs = 2;                           ///< lockstep groups run at the same time (threads)
  std::function<void(std::string_view)> log;  ///< progress lines ("" = silent)
  std::string gnuplot = "gnuplot";        ///< plotting program
  /// `--set KEY=VALUE` overrides applied to every lockstep run's scenario after the study set its
  /// own keys (scenario::WithOverrides, in Preflight); checked like a file.
  std::vector<std::string> overrides;
  /// Progress with an ETA of the lockstep batches (null: none); the main program decides.
  ProgressLine* progress = nullptr;
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
  std::vector<double> paper_peak_kN;    ///< the reference of docs/experiments.md E6
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

/// One of the paper's claims (docs/experiments.md E3) checked on our table.
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

/// Controller settings of a Table 1 row: the kind alone; with the delay it compensates (poly3,
/// lead) [ms]; or with its design model (a preset: "0.0A", "2.5A", "avg").
control::ControllerConfig ControllerKind(const std::string& kind);
control::ControllerConfig ControllerDelay(const std::string& kind, double delay_ms);
control::ControllerConfig ControllerModel(const std::string& kind, const std::string& preset);

// --- Frequency-domain studies: Fig. 6 (E1) and Figs. 7-8 (E2) ------------------------------

/// A measured or modelled frequency response on a grid, as the paper plots it.
struct BodeCurve {
  std::string name;                 ///< legend entry
  std::vector<double> f_hz;         ///< frequencies [Hz], > 0
  std::vector<double> magnitude;    ///< |G| [mm/mm]
  std::vector<double> phase_deg;    ///< unwrapped phase [deg]
  std::vector<double> lag_ms;       ///< time lag -phase / (2 pi f) [ms] (> 0: the output lags)
  std::vector<double> coherence;    ///< gamma^2 (1 for a model)
};
/// The H1 estimate on (0, f_max_hz], phase unwrapped from the lowest frequency up.
BodeCurve BodeFromEstimate(const std::string& name, const signal::FrequencyResponseEstimate& est,
                           double f_max_hz);
/// A model's response on the grid f_hz: continuous if zoh_dt_s = 0, else that of its
/// zero-order-hold discretisation at zoh_dt_s (what a ZOH plant sampled at the same rate shows).
BodeCurve BodeFromModel(const std::string& name, const ident::PoleModel& model, const std::vector<double>& f_hz,
                        double zoh_dt_s);

/// The excitation of E1 and E2: BLWN 0-50 Hz, RMS 0.254 mm, seed 1, 2 s discarded, faded in over
/// 0.5 s (the command of E1; the desired displacement of E2).
signal::SignalSpec FrequencyExcitation();

/// The scenario of one frequency-domain run (E1, E2): desired r = BLWN 0-50 Hz, RMS 0.254 mm,
/// seed 1, faded in over 0.5 s; the damper attached at the condition's constant current
/// ("0.0A" or "2.5A"); the plant ("linear": Eq. 28 or 29).
scenario::Scenario FrequencyScenario(const std::string& condition, const control::ControllerConfig& controller,
                                     const std::string& plant, double duration_s);

struct Fig6Model {
  std::string condition;            ///< "0.0A", "2.5A", "avg" (the fit of the averaged response)
  models::ServoModel3 paper;      ///< Eq. 28, 29, 30
  ident::FitSummary fit;            ///< our 3-pole fit (ZOH-aware)
  double max_diff_pct = 0.0;        ///< largest |ours / paper - 1| over K, p, b, c [%]
};
struct Fig6Result {
  std::vector<BodeCurve> measured;  ///< H1 of G_yu at 0.0 A and 2.5 A
  std::vector<Fig6Model> models;    ///< 0.0A, 2.5A, avg
  double tolerance_pct = 0.0;       ///< E1: 3 % on the linear plant, 8 % on the physical one
  Claim verdict;                    ///< E1 on the 0.0 A and 2.5 A fits
};
/// E1: BLWN 0-50 Hz, RMS 0.254 mm commanded with no controller at 0.0 A and 2.5 A (60 s;
/// --quick 16 s); H1 with coherence; 3-pole fits over 0.5-40 Hz. Writes fig6.png (magnitude,
/// phase, time lag with the fitted models overlaid), fig6.csv (the measured curves),
/// fig6_models.csv (condition,parameter,paper,ours,diff_pct), fig6.md and runs/.
Fig6Result ReproduceFig6(const ReproduceOptions& opts);

struct Fig78Result {
  std::string condition;            ///< "0.0A" (Fig. 7) or "2.5A" (Fig. 8)
  std::vector<BodeCurve> curves;    ///< G_yr per controller, in Table 1's order
  std::vector<Claim> checks;        ///< E2's statements, measured on the curves
};
/// The Table 2 controllers of one condition, in order ("0.0A" or "2.5A").
std::vector<Table2Controller> ControllersOf(const std::string& condition);
/// E2: the same BLWN as the desired displacement through each controller of the condition
/// (figure "fig7": 0.0 A, "fig8": 2.5 A); G_yr by H1. Writes <figure>.png (magnitude, phase and
/// time lag, 0-50 Hz, one curve per controller), <figure>.csv
/// (controller,f_hz,magnitude,phase_deg,time_lag_ms,coherence), <figure>.md and runs/.
Fig78Result ReproduceFig78(const ReproduceOptions& opts, const std::string& figure);

}  // namespace rths::report
