#pragma once
/// @file Fig. 11 (docs/experiments.md E5): the 9-story building with semiactive control under El
/// Centro, 3 controllers x 3 semiactive modes of RTHS and the pure numerical simulation of each
/// mode. The base scenario comes from the source tree (scenarios/fig11_base.toml) and is varied in
/// code; every variant is written in full into its run folder (studies/batch.h).
#include <filesystem>
#include <string>
#include <vector>

#include "io/plot.h"
#include "scenario/scenario.h"
#include "studies/study.h"

namespace rths::studies {

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
  std::vector<Claim> claims;        ///< CheckFig11Claims (also in fig11.md)
  double wall_s = 0.0;
};

/// The paper's statements on Fig. 11 checked on the runs (docs/reproduce_fig11.md):
///   (1) every compensated RTHS stays bounded under clipped-optimal switching (no run stopped, the
///       force error finite);
///   (2) under clipped-optimal control G_FF,avgA + LQG's damper force is the closest to the
///       numerical simulation's (Eq. 31 with the numerical force as reference) of the three;
///   (3) the predicted acceleration (Eq. 20) and velocity (Eq. 21) are at least as accurate as the
///       paper's 1.81 % and 0.0061 % in every RTHS run.
std::vector<Claim> CheckFig11Claims(const Fig11Result& res);
/// Runs the 9 RTHS runs and the 3 numerical ones; writes fig11_summary.json ({"runs": [...]}, the
/// 9 RTHS runs), fig11_numerical.json (same keys, the 3 numerical runs), fig11.md, the PNGs
/// (fig11_damper_<mode>.png: displacement and force histories, force-displacement and
/// force-velocity loops, RTHS vs numerical; fig11_stories.png: peak drifts and accelerations per
/// story) and runs/.
Fig11Result ReproduceFig11(const ReproduceOptions& opts);

/// Fig. 11's stories figure from a result: peak story drift [mm] and peak absolute floor
/// acceleration [mm/s^2] per story, for each semiactive mode, numerical (dashed) and RTHS with
/// G_FF,avgA + LQG (solid); the legend beside the axes.
io::Figure Fig11StoriesFigure(const Fig11Result& res);

}  // namespace rths::studies
