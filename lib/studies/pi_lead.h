#pragma once
/// @file `pi_lead` of the extended Table 2 (docs/reproduce_table2.md "--extended"): a PI + phase lead
/// designed for a servohydraulic model by a written rule, in the manner of the RTHS benchmark's
/// example controller.
#include <string>
#include <vector>

#include "control/controller_config.h"
#include "models/servo_linear.h"

namespace rths::studies {

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

}  // namespace rths::studies
