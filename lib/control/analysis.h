#pragma once
/// @file Closed-loop analysis of a tracking controller on a discrete plant model (docs/controllers.md).
///
/// Conventions: the controller is u_k = F(z) r_k + C_fb(z) e_k with e_k = y_k - r_k (ControllerLti),
/// the plant y = G_d(z) u (ZOH, strictly proper). With negative-feedback sign the loop transfer is
///   L(z) = -C_fb(z) G_d(z),  S(z) = 1 / (1 + L(z)),
/// evaluated on z = e^{j w dt}. Tracking (E2):  G_yr(z) = G_d (F - C_fb) / (1 - C_fb G_d)  (= F G_d
/// without feedback).
#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "control/lti.h"
#include "control/tracking_controller.h"

namespace rths::control {

/// One gain crossover |L| = 1.
struct Crossover {
  double f_hz = 0.0;
  double phase_margin_deg = 0.0;  ///< 180 + arg L, wrapped to (-180, 180]
  double delay_margin_s = 0.0;    ///< extra pure delay that closes the margin: PM [rad] / w
};

struct LoopAnalysis {
  Eigen::VectorXcd closed_loop_poles;  ///< eigenvalues of plant + controller, dim n_plant + n_controller
  double spectral_radius = 0.0;        ///< max |pole|
  bool stable = false;                 ///< spectral_radius < 1
  std::vector<Crossover> crossovers;   ///< every gain crossover in (0, Nyquist), increasing f
  Crossover critical;                  ///< the crossover of least delay margin (zeros if none)
  double peak_sensitivity_db = 0.0;    ///< max |S| over (0, Nyquist) [dB]
  double peak_sensitivity_hz = 0.0;    ///< where it is reached [Hz]
};

/// Analyses the feedback loop of C_fb (e -> u_FB) around `plant`. Both must share dt_s.
LoopAnalysis AnalyzeLoop(const DiscreteSs& fb, const DiscreteSs& plant);

/// G_yr(e^{j 2 pi f dt}) of `c` on `plant` (formula above).
std::complex<double> TrackingResponse(const ControllerLti& c, const DiscreteSs& plant, double f_hz);
/// Time lag -arg G_yr / w [s] at f_hz > 0, the phase unwrapped continuously from 0.01 Hz.
double TrackingLagS(const ControllerLti& c, const DiscreteSs& plant, double f_hz);

}  // namespace rths::control
