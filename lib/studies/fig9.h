#pragma once
/// @file Fig. 9 (docs/experiments.md E4): the SDOF RTHS parametric study, 6 natural frequencies x
/// 6 controllers. The base scenario comes from the source tree (scenarios/fig9_base.toml) and is
/// varied in code; every variant is written in full into its run folder (studies/batch.h).
#include <filesystem>
#include <string>
#include <vector>

#include "io/plot.h"
#include "scenario/scenario.h"
#include "studies/study.h"

namespace rths::studies {

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

/// Fig. 9's figure from a result: RMS error against natural frequency, one curve per controller
/// (G_FF,0.0A, the proposed, prominent), stopped pairs ringed.
io::Figure Fig9Figure(const Fig9Result& res, const std::string& plant, bool quick);

}  // namespace rths::studies
