#pragma once
/// @file The two RTHS studies of the paper (docs/experiments.md E4 and E5): the SDOF parametric study of
/// Fig. 9 and the 9-story building with semiactive control of Fig. 11. Both load a base scenario
/// from the source tree (scenarios/fig9_base.toml, scenarios/fig11_base.toml), vary it in code,
/// write every variant in full into its run folder (report/batch.h) and run the lockstep groups
/// in parallel threads, each on its own memq:// instance.
#include <filesystem>
#include <string>
#include <vector>

#include "report/batch.h"
#include "report/reproduce.h"
#include "scenario/scenario.h"

namespace rths::report {

/// The "stopped" field of a study: "no" for a run that ran to the end, else the reason (the
/// safety monitor's message, or the failure) on one line.
std::string StoppedText(const RunResult& r);

// --- Fig. 9 (E4): SDOF RTHS parametric study ---------------------------------------------

struct Fig9Controller {
  std::string name;                      ///< Table 2's name for 0.0 A, e.g. "3rd Poly 8ms"
  control::ControllerConfig controller;
};
/// The six controllers of Table 2's 0.0 A rows, in the paper's order.
std::vector<Fig9Controller> Fig9Controllers();
/// 0.5, 1, 5, 10, 20, 30 Hz.
std::vector<double> Fig9FrequenciesHz();
/// RMS of the BLWN ground acceleration [mm/s^2]: 1000 (0.5, 1 Hz), 1500 (5 Hz), 2000 (10-30 Hz).
double Fig9GroundRms(double f_hz);
/// One run: `base` (fig9_base.toml) at natural frequency f_hz with the controller, the plant
/// ("physical" | "linear" | "ideal") and the duration [s].
scenario::Scenario Fig9Scenario(const scenario::Scenario& base, double f_hz, const Fig9Controller& c,
                                const std::string& plant, double duration_s);
/// Record lengths [s]: full 60 s; --quick 6 s.
inline constexpr double kFig9FullS = 60.0;
inline constexpr double kFig9QuickS = 6.0;

struct Fig9Row {
  double f_hz = 0.0;
  std::string controller;
  double rms_pct = 0.0;          ///< Eq. 31 over the logged steps (up to the stop, if stopped)
  std::string stopped = "no";    ///< "no" or the safety monitor's reason
  double peak_error_mm = 0.0;    ///< max |r - y|
  double peak_u_mm = 0.0;        ///< max |u|
  double peak_y_mm = 0.0;        ///< max |y|
  double peak_f_kN = 0.0;        ///< max |f|
  std::filesystem::path run_dir;
};
struct Fig9Result {
  std::vector<Fig9Row> rows;     ///< frequency-major, controllers in Fig9Controllers() order
  double wall_s = 0.0;
};
/// Runs the 36 (frequency, controller) pairs and writes fig9.csv (f_hz,controller,rms_pct,stopped),
/// fig9.md, fig9.png (RMS error vs natural frequency, log axes, stopped pairs marked) and runs/.
Fig9Result ReproduceFig9(const ReproduceOptions& opts);

// --- Fig. 11 (E5): 9-story building, El Centro, semiactive control ------------------------

struct Fig11Controller {
  std::string name;                      ///< "3rd Poly 9ms" | "Bumpless + LP" | "G_FF,avgA + LQG"
  control::ControllerConfig controller;
};
std::vector<Fig11Controller> Fig11Controllers();
/// "passive_off", "passive_on", "clipped_optimal".
std::vector<std::string> Fig11SemiactiveModes();
/// One run: `base` (fig11_base.toml) with the controller, the semiactive mode, the plant and the
/// duration [s] (<= the record's 31.2 s).
scenario::Scenario Fig11Scenario(const scenario::Scenario& base, const Fig11Controller& c,
                                 const std::string& semiactive, const std::string& plant, double duration_s);
inline constexpr double kFig11FullS = 31.2;
inline constexpr double kFig11QuickS = 8.0;

struct Fig11Run {
  std::string controller;        ///< "Numerical" for the pure numerical simulation
  std::string semiactive;
  std::string stopped = "no";
  std::vector<double> peak_drift_mm;        ///< 9 stories, from desired_t x_mm (x_i - x_{i-1})
  std::vector<double> peak_abs_accel_mps2;  ///< 9 floors, from desired_t abs_acc_mm_s2
  double damper_peak_force_kN = 0.0;        ///< one damper, max |f_k|
  double damper_peak_disp_mm = 0.0;         ///< max |y_k|
  double force_rths_vs_numerical_nrmse_pct = 0.0;  ///< Eq. 31: numerical f as reference
  double accel_extrapolation_rms_err_pct = 0.0;
  double velocity_prediction_rms_err_pct = 0.0;
  double wall_s = 0.0;
  std::filesystem::path run_dir;
};
struct Fig11Result {
  std::vector<Fig11Run> runs;       ///< the 9 RTHS runs, controller-major
  std::vector<Fig11Run> numerical;  ///< the 3 pure numerical simulations (plant.kind = "ideal")
  double wall_s = 0.0;
};
/// Runs the 9 RTHS runs and the 3 numerical ones; writes fig11_summary.json ({"runs": [...]}, the
/// 9 RTHS runs), fig11_numerical.json (same keys, the 3 numerical runs), fig11.md, the PNGs
/// (fig11_damper_<mode>.png: displacement and force histories, force-displacement and
/// force-velocity loops, RTHS vs numerical; fig11_stories.png: peak drifts and accelerations per
/// story) and runs/.
Fig11Result ReproduceFig11(const ReproduceOptions& opts);

}  // namespace rths::report
