#pragma once
/// @file `ambc`: adaptive model-based compensation (G. A. Fermandois, "Application of model-based
/// compensation methods to real-time hybrid simulation benchmark", Mech. Syst. Signal Process. 131
/// (2019) 394-416), in the robust form of C. Galmez and G. Fermandois, "Robust adaptive model-based
/// compensator for the real-time hybrid simulation benchmark", Struct. Control Health Monit. 2022,
/// as its public code runs it (FermandoisLab/RobustAMBCvRTHS, "1. AMB_Linear/AMB_L_1_vRTHS.m" and
/// AMB_L_8_vRTHS_simulation.slx; docs/controllers.md).
///
/// Model and compensator: G(s) = 1 / (a0 + a1 s + a2 s^2 + a3 s^3), inverted with backward
/// differences so that it is causal:
///   u_k = theta_s^T phi_t,k,  theta = [a0 [-], a1 [s], a2 [s^2], a3 [s^3]],
///   phi_t,k = [x_t, D1 x_t, D2 x_t, D3 x_t]_k                              [mm, mm/s, mm/s^2, mm/s^3]
/// with D1 = [1 -1]/dt, D2 = [1 -2 1]/dt^2, D3 = [1 -3 3 -1]/dt^3 on x_t,k .. x_t,k-3 of the
/// unfiltered target ("difference", zero before the first step), or [r, r', r'', r'''] of
/// Eqs. 20-22 ("integrator").
///
/// Adaptation (the normalised gradient law, Ioannou & Sun's form with m^2 = 1 + phi^T phi), in
/// SI units because the normalisation mixes 1 with phi^T phi and the published gains are SI:
///   z_k   = F(u)_k [m],   phi_k = [F(y), D1 F(y), D2 F(y), D3 F(y)]_k [m, m/s, m/s^2, m/s^3],
///   eps   = (z - theta_s^T phi) / (1 + phi^T phi),
///   d theta / dt = Gamma eps phi,   Gamma = diag(10^gain_log10),
///   theta_s = min(max(theta, lower), upper)   (a saturation after the integrator: theta itself
///             is not limited and can wind up beyond the bounds, as the reference),
/// with F the digital Butterworth low-pass of order filter_order at filter_hz (MATLAB's
/// butter(n, fc/(fs/2)): bilinear with prewarping, signal::ButterworthLowpass, run as sections).
/// The series-parallel (inverse-model) error: the filtered command against the model's
/// prediction of it from the filtered measured response; a plant exactly in the family gives
/// eps = 0 at theta = theta*.
///
/// Step k: u_k with theta_s(t_k); then y_k, u_k into F, phi_k, z_k, and theta is carried from t_k
/// to t_{k+1} with phi_k, z_k held (the reference integrates with ode4 at dt, inputs held).
/// Held inputs make the law linear in theta between saturations: with the free set
/// S = {i : lower_i <= theta_i <= upper_i} at t_k (saturated a_i are constant in theta_s),
///   e(t) = z - theta_s(t)^T phi  obeys  e' = -mu e,  mu = sum_{i in S} Gamma_i phi_i^2 / m^2,
/// so over the step, exactly,
///   theta_i(t_k + dt) = theta_i(t_k) + Gamma_i phi_i e(t_k) / m^2 * (1 - exp(-mu dt)) / mu
/// (dt when mu = 0), for every i (the saturated ones wind up by the same integral). This is the
/// flow ode4 approximates: the two agree to about (mu dt)^4 / 120 in the change per step while
/// RK4 is stable, but RK4 is unstable once mu dt > 2.785, which the published gains reach in slow
/// motion of a few mm (mu dt ~ Gamma_0 x_m^2 dt, Gamma_0 = 10^8.4: from |x_m| ~ 7 mm at 4096 Hz,
/// 5 mm at 2048 Hz; with RK4 steps, a 10 mm 0.3 Hz sine on a 20 ms lag sends theta_0 to 2.7). The
/// exact flow is stable for any mu dt.
#include <array>

#include "control/tracking_controller.h"
#include "signal/butterworth.h"

namespace rths::control {

/// The immutable design of an `ambc` controller.
struct AmbcDesign {
  AmbcConfig config;
  double dt_s = 0.0;
  std::array<double, 4> initial{};  ///< theta(0): Eq. 19's (a0..a3) of controller.model, or `initial`
  std::array<double, 4> gamma{};    ///< diag(Gamma) = 10^gain_log10 (0 for -inf: not adapted) [SI]
  signal::Sos filter;               ///< F, on u and y
};

/// Checks `cfg` and designs at dt_s (`model` is used for start = "model"). Throws rths::Error
/// naming the scenario key, with the allowed range: "run.dt_s"; "controller.model" (start =
/// "model": K, p, b, c not finite and > 0); "controller.ambc.initial" (start = "given": not
/// finite or outside [lower, upper]); "controller.ambc.lower" / ".upper" (NaN, lower = +inf,
/// upper = -inf, lower above upper, or the model's coefficients outside them);
/// "controller.ambc.gain_log10" (not in [-30, 30] and not -inf); ".filter_order" (not in
/// [1, 8]); ".filter_hz" (not in (0, 0.5/dt)).
AmbcDesign MakeAmbcDesign(const AmbcConfig& cfg, const models::ServoModel3& model, double dt_s);

/// The per-step state of an `ambc` controller.
struct AmbcState {
  signal::SosFilter filter_y;        ///< F on y [m] (sized by AmbcAtRest, never resized)
  signal::SosFilter filter_u;        ///< F on u [m]
  std::array<double, 3> r_past_mm{};   ///< x_t,k-1 .. x_t,k-3 [mm] ("difference")
  std::array<double, 3> yf_past_m{};   ///< F(y)_k-1 .. F(y)_k-3 [m]
  std::array<double, 4> theta{};       ///< the integrator's state (not saturated)
  std::array<double, 4> theta_used{};  ///< theta_s used for u_k
  double u_mm = 0.0;                   ///< u_k of the last AmbcCommand [mm]
  std::array<double, 4> phi{};         ///< phi_k of the last update [m, m/s, m/s^2, m/s^3]
  double z_m = 0.0;                    ///< z_k of the last update [m]
  double eps = 0.0;                    ///< eps at t_k of the last update [-]
};

/// The state at rest (theta = design.initial). Allocates the filter states once.
AmbcState AmbcAtRest(const AmbcDesign& d);

/// First half of step k: theta_s = sat(theta), u_k = theta_s^T phi_t,k (kept in s->u_mm). Uses no
/// measurement of step k. Allocates nothing.
Command AmbcCommand(const AmbcDesign& d, AmbcState* s, const Derivatives& target);
/// Second half of step k: y_k and u_k through F, phi_k, z_k, then theta carried over the step
/// (IntegrateGradientLaw). Allocates nothing.
void AmbcUpdate(const AmbcDesign& d, AmbcState* s, double y_mm);

/// theta from t_k to t_k + dt under the gradient law with phi [SI] and z [m] held (the exact flow
/// above); returns eps at t_k. Allocates nothing.
double IntegrateGradientLaw(const AmbcDesign& d, const std::array<double, 4>& phi, double z_m,
                            std::array<double, 4>* theta);

/// `ambc` (the recursion above).
class AmbcController final : public TrackingController {
 public:
  explicit AmbcController(AmbcDesign design) : design_(std::move(design)), state_(AmbcAtRest(design_)) {}
  Command Step(const Derivatives& d, const Measurement& m) override {
    const Command c = AmbcCommand(design_, &state_, d);
    AmbcUpdate(design_, &state_, m.y_mm);
    return c;
  }
  /// The compensator with theta fixed at its start value (AdaptiveFir), no feedback.
  ControllerLti Linearize(double current_A) const override;
  const AmbcDesign& design() const { return design_; }
  const AmbcState& state() const { return state_; }

 private:
  const AmbcDesign design_;
  AmbcState state_;
};

}  // namespace rths::control
