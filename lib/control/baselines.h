#pragma once
/// @file The delay-compensation baselines of Table 1 (docs/models.md section 3), both designed for
/// the DC time lag tau of the servo model (8 / 9 / 10 ms for Eqs. 28 / 30 / 29) and fed with the
/// desired displacement r only.
#include <array>

#include "control/tracking_controller.h"

namespace rths::control {

/// Third-order polynomial extrapolation (Horiuchi et al. 1996): the cubic through r_k .. r_{k-3}
/// (spacing dt) evaluated tau ahead. With alpha = tau / dt:
///   c0 = (alpha+1)(alpha+2)(alpha+3)/6,   c1 = -alpha(alpha+2)(alpha+3)/2,
///   c2 = alpha(alpha+1)(alpha+3)/2,        c3 = -alpha(alpha+1)(alpha+2)/6   (sum = 1);
/// tau = 8 ms at 2 kHz: [969, -2736, 2584, -816].
struct Poly3Design {
  double delay_s = 0.0;          ///< tau [s]
  double alpha = 0.0;            ///< tau / dt [-]
  std::array<double, 4> c{};     ///< c0 .. c3 [-]
  double nyquist_gain = 0.0;     ///< |c0 - c1 + c2 - c3|, the gain at the Nyquist frequency [-]
};
/// Throws rths::Error("controller.delay_ms") unless delay_s > 0, and unless dt_s > 0.
Poly3Design MakePoly3(double delay_s, double dt_s);

/// `poly3`: u_k = c0 r_k + c1 r_{k-1} + c2 r_{k-2} + c3 r_{k-3} (r = 0 before the first step).
class PolynomialExtrapolation final : public TrackingController {
 public:
  PolynomialExtrapolation(const Poly3Design& design, double dt_s) : design_(design), dt_s_(dt_s) {}
  Command Step(const Derivatives& d, const Measurement& m) override;
  ControllerLti Linearize(double current_A) const override;
  const Poly3Design& design() const { return design_; }

 private:
  const Poly3Design design_;
  const double dt_s_;
  std::array<double, 3> past_{};  ///< r_{k-1}, r_{k-2}, r_{k-3} [mm]
};

/// Lead compensator C(s) = (T_z s + 1) / (T_p s + 1), T_z = tau + T_p: phase lead ~ w tau at low
/// frequency. Tustin, s = c (1 - z^-1) / (1 + z^-1), c = 2 / dt:
///   u_k = b0 r_k + b1 r_{k-1} - a1 u_{k-1},
///   b0 = (c T_z + 1) / (c T_p + 1),  b1 = (1 - c T_z) / (c T_p + 1),  a1 = (1 - c T_p) / (c T_p + 1);
/// tau = 8 ms, T_p = 0.5 ms at 2 kHz: b0 = 11.6667, b1 = -11.0000, a1 = -0.33333.
struct LeadDesign {
  double delay_s = 0.0;  ///< tau [s]
  double tp_s = 0.0;     ///< T_p [s]
  double tz_s = 0.0;     ///< T_z = tau + T_p [s]
  double b0 = 0.0, b1 = 0.0, a1 = 0.0;
};
/// Throws rths::Error("controller.delay_ms" / "controller.lead_tp_ms") unless both are > 0.
LeadDesign MakeLead(double delay_s, double tp_s, double dt_s);

/// `lead`: the Tustin lead compensator on r (state at rest before the first step).
class LeadCompensator final : public TrackingController {
 public:
  LeadCompensator(const LeadDesign& design, double dt_s) : design_(design), dt_s_(dt_s) {}
  Command Step(const Derivatives& d, const Measurement& m) override;
  ControllerLti Linearize(double current_A) const override;
  const LeadDesign& design() const { return design_; }

 private:
  const LeadDesign design_;
  const double dt_s_;
  double r_prev_ = 0.0;  ///< r_{k-1} [mm]
  double u_prev_ = 0.0;  ///< u_{k-1} [mm]
};

}  // namespace rths::control
