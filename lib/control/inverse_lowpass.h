#pragma once
/// @file Model inverse with a low-pass filter (Carrion & Spencer 2007; docs/models.md section 3):
/// the `ff_lp` and `bumpless_lp` controllers of Table 1.
///
/// C(s) = LP(s) G^-1(s),  G^-1(s) = (s + p)(s^2 + b s + c) / K  (Eq. 16, N = 3),
/// LP(s) = Butterworth low-pass of order N >= 3 at w_c = 2 pi f_c:
///   LP(s) = prod_k w_c^2 / (s^2 + 2 sin(theta_k) w_c s + w_c^2) [x w_c / (s + w_c) if N odd],
///   theta_k = (2k + 1) pi / (2N),  k = 0 .. floor(N/2) - 1.
/// The product is proper. It is factored into analog sections (s^2 + b s + c) over the least damped
/// Butterworth pair, (s + p) over the real pole (N odd) or the next pair (N even), the remaining
/// pairs alone, each scaled to unit DC gain, and the overall DC gain p c / K put in the first.
/// Each section is discretised by the plain bilinear (Tustin) substitution
///   s = (2 / dt) (1 - z^-1) / (1 + z^-1)   (no prewarping),
/// which is exact for the product: C_d(e^{j w dt}) = C(j (2/dt) tan(w dt / 2)). The low-pass delays
/// by its DC group delay (2 / w_c for N = 3: about 1 ms at 318 Hz), which no model inverse removes.
#include <complex>

#include "control/tracking_controller.h"
#include "signal/butterworth.h"

namespace rths::control {

struct InverseLowpassDesign {
  models::ServoModel3 model;  ///< the inverted servo model
  int order = 3;                ///< Butterworth order N
  double cutoff_hz = 0.0;       ///< f_c [Hz]
  double dt_s = 0.0;            ///< Tustin step [s]
  signal::Sos sos;              ///< C_d(z) as second-order sections (DF-II-T; signal::SosStep)
  double dc_group_delay_s = 0.0;  ///< LP(s)'s group delay at DC, sum(-Re p_i) / w_c^2 (2 / w_c for N = 3) [s]

  /// The continuous design C(j w) = LP(j w) G^-1(j w) at f_hz [Hz].
  std::complex<double> Analog(double f_hz) const;
};

/// Designs C_d(z). `key` names the model in errors (e.g. "controller.model_low"). Throws rths::Error
/// naming "controller.lp_order" unless order is in [3, 8], "controller.lp_cutoff_hz" unless
/// 0 < cutoff_hz < 0.5 / dt_s, `key` unless K, p, b, c > 0.
InverseLowpassDesign MakeInverseLowpass(const models::ServoModel3& model, int order, double cutoff_hz,
                                        double dt_s, const std::string& key);

/// `ff_lp`: u_k = C_d(z) r_k (r only; filter at rest before the first step).
class InverseLowpass final : public TrackingController {
 public:
  explicit InverseLowpass(InverseLowpassDesign design);
  Command Step(const Derivatives& d, const Measurement& m) override;
  ControllerLti Linearize(double current_A) const override;
  const InverseLowpassDesign& design() const { return design_; }

 private:
  const InverseLowpassDesign design_;
  signal::SosFilter state_;
};

/// `bumpless_lp` (Carrion & Spencer 2007): the low and high designs run in parallel on the same r at
/// all times (their states are never switched or reset) and are blended by the damper current:
///   u_k = (1 - lambda_k) C_low(z) r_k + lambda_k C_high(z) r_k,
///   lambda_k = clamp(i_k / current_high_A, 0, 1),  i_k = Measurement::current_A of sample k
/// (the effective current after Eq. 40, as the plant reports it).
class BumplessInverseLowpass final : public TrackingController {
 public:
  /// Throws rths::Error("controller.current_high_A") unless current_high_A > 0.
  BumplessInverseLowpass(InverseLowpassDesign low, InverseLowpassDesign high, double current_high_A);
  Command Step(const Derivatives& d, const Measurement& m) override;
  ControllerLti Linearize(double current_A) const override;
  const InverseLowpassDesign& low() const { return low_; }
  const InverseLowpassDesign& high() const { return high_; }
  double Lambda(double current_A) const;

 private:
  const InverseLowpassDesign low_, high_;
  const double current_high_A_;
  signal::SosFilter state_low_, state_high_;
};

}  // namespace rths::control
