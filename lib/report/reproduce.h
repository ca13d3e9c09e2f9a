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
#include <optional>
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
  /// The rths checkout the user named (the tool's RTHS_SOURCE_DIR): searched first for the studies'
  /// base scenarios (scenarios/fig9_base.toml, ...); "" only the search of io::FindSourceFile.
  std::filesystem::path source_dir;
  /// `--set KEY=VALUE` overrides applied to every lockstep run's scenario after the study set its
  /// own keys (scenario::WithOverrides, in Preflight); checked like a file.
  std::vector<std::string> overrides;
  /// Progress with an ETA of the lockstep batches (null: none); the main program decides.
  ProgressLine* progress = nullptr;
  /// table2 only: also run the extended table (table2_extended.csv/.md/.png): the field's adaptive
  /// compensators and a PI + phase lead beside the paper's proposed controllers. The paper's 36
  /// rows and their files are the same with or without it.
  bool extended = false;
};

/// Now, as "YYYY-MM-DD HH:MM UTC": the stamp of a reproduction's Markdown.
std::string UtcStamp();

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

// --- Table 2, extended (issue 25; docs/reproduce_table2.md "--extended") ---------------------

/// `pi_lead`: a PI feedback C(s) = Kp + Ki/s and a phase lead T(s) = k (s - zero)/(s - pole) on the
/// reference (u = C (T r - y), an `lti` controller, Tustin at the run's dt), designed on a design
/// model by a fixed rule (DesignPiLead), in the manner of the RTHS benchmark's example controller.
struct PiLeadDesign {
  models::ServoModel3 model;         ///< the design model (ZOH at dt_s)
  double dt_s = 0.0;
  // The rule's constants.
  double target_pm_deg = 60.0;       ///< phase margin of the PI loop
  double max_sensitivity_db = 6.02;  ///< its peak sensitivity bound (Ms <= 2: gain margin >= 6 dB)
  double safety_deg = 5.0;           ///< added to the PI loop's margin for the lead (the benchmark's)
  double fac = 2.0;                  ///< the lead's pole moved out by fac, k = a fac (the benchmark's)
  double lag_hz = 1.0;               ///< where the PI loop's remaining lag is measured
  // The PI.
  double kp = 0.0, ki = 0.0;         ///< [-], [1/s]
  double pi_crossover_hz = 0.0;      ///< the crossover the rule chose
  double pi_phase_margin_deg = 0.0;  ///< of the PI loop (AnalyzeLoop)
  double pi_delay_margin_ms = 0.0;
  double pi_peak_sensitivity_db = 0.0;
  double pi_spectral_radius = 0.0;   ///< of the closed loop's poles
  int pi_crossovers = 0;             ///< gain crossovers of the PI loop (the rule requires one)
  bool pi_stable = false;
  double pi_lag_ms = 0.0;            ///< lag of y behind r at lag_hz with T = 1 [ms]
  // The lead.
  double phi_deg = 0.0;              ///< pi_phase_margin_deg + safety_deg
  double a = 0.0;                    ///< (1 + sin phi)/(1 - sin phi)
  double tl_s = 0.0;                 ///< Tl = pi_lag / (a - 1/fac): the lead's low-frequency advance
                                     ///< a Tl - Tl/fac equals the PI loop's lag
  double w_m_rad_s = 0.0;            ///< 1/(Tl sqrt a)
  double zero = 0.0, pole = 0.0;     ///< T's zero -1/(a Tl) and pole -fac/Tl [1/s]
  double k = 0.0;                    ///< a fac (T(0) = 1)
  // The whole controller on the design model (G_yr, e.g. lag_ms[1] at 5 Hz).
  std::vector<double> check_hz;      ///< 1, 5, 10, 15 Hz
  std::vector<double> gyr_magnitude, gyr_lag_ms;
  control::ControllerConfig controller;  ///< kind "lti", ready to run
  /// The rule and the numbers, in a few lines of text (for table2_extended.md and the console).
  std::string Describe() const;
};
/// The rule (docs/reproduce_table2.md): (1) the PI: for every crossover frequency w on a grid below
/// Nyquist, the Kp >= 0, Ki > 0 that give the discrete loop C G (Tustin PI, ZOH model) |L| = 1 and
/// a phase margin target_pm_deg at w; of these, the largest Ki (the closed loop's low-frequency lag
/// is 1/(Ki G(0))) whose loop has a peak sensitivity <= max_sensitivity_db; checked with
/// control::AnalyzeLoop: stable, one crossover, the margin, the peak. (2) the lead, with the
/// benchmark's formulas: phi = the PI loop's margin + safety_deg, a = (1 + sin phi)/(1 - sin phi),
/// and Tl (the one number the benchmark chose by hand through w_m) such that the lead's
/// low-frequency advance a Tl - Tl/fac equals the PI loop's lag at lag_hz; pole = -fac/Tl, zero =
/// -1/(a Tl), k = a fac. Throws rths::Error if no PI meets the margin with one stable crossover.
PiLeadDesign DesignPiLead(const models::ServoModel3& model, double dt_s);

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
