#pragma once
/// @file Configuration of the outer-loop tracking controller (procs/controller; Table 1 of the
/// paper): plain structs with defaults, filled by the scenario's [controller] table.
#include <array>
#include <string>
#include <vector>

#include "core/names.h"
#include "models/servo_linear.h"

namespace rths::control {

/// LQG feedback on the deviation system (Eqs. 23-27, docs/models.md section 4). The cost is
/// sum(q e_k^2 + u_FB,k^2); the disturbance is white noise of intensity W through the
/// second-order shaping filter of Eq. 27; the measurement noise has intensity V.
struct LqgConfig {
  double q = 10.0;       ///< weight on the tracking error, (0, 1e12]
  double w_f_hz = 3.0;   ///< shaping filter frequency omega_f / 2 pi [Hz], (0, 1000]
  double xi_f = 0.7;     ///< shaping filter damping (peak), (0, 10]
  double eta_f = 0.5;    ///< shaping filter zero (roll-off), [0, 100]
  double W = 1.0;        ///< process-noise intensity, (0, 1e12]
  double V = 1.0;        ///< measurement-noise intensity, (0, 1e12]
  bool operator==(const LqgConfig&) const = default;
};

/// A transfer function num(x) / den(x), coefficients in descending powers of x (s or z), as
/// MATLAB's tf and tfdata write them: num = [b_m, ..., b_1, b_0] is b_m x^m + ... + b_0. Leading
/// zeros are allowed (tfdata of a discrete system pads num with them to den's length). Both empty:
/// the transfer function 1.
struct TfCoefficients {
  std::vector<double> num;
  std::vector<double> den;
  bool Empty() const { return num.empty() && den.empty(); }
  bool operator==(const TfCoefficients&) const = default;
};

/// The variable the coefficients of an `lti` controller are given in.
enum class TfDomain { kS, kZ };
inline constexpr std::array<Named<TfDomain>, 2> kTfDomainNames = {{{TfDomain::kS, "s"}, {TfDomain::kZ, "z"}}};
/// How an s-domain transfer function becomes a discrete one at run.dt_s.
enum class Discretisation { kTustin, kZoh };
inline constexpr std::array<Named<Discretisation>, 2> kDiscretisationNames = {
    {{Discretisation::kTustin, "tustin"}, {Discretisation::kZoh, "zoh"}}};

/// `lti`: u = C (T r - y), a controller from transfer functions (docs/controllers.md, "A controller
/// from transfer functions"). Every signal is a displacement [mm], so C and T are dimensionless
/// (mm/mm = m/m: a gain designed in metres is the same number here).
struct LtiConfig {
  TfCoefficients feedback;   ///< C: the error e = T r - y [mm] -> u [mm]; empty: 1
  TfCoefficients reference;  ///< T: the desired displacement r [mm] -> the filtered target [mm]; empty: 1
  TfDomain domain = TfDomain::kS;                      ///< "s" (continuous) or "z" (discrete at run.dt_s)
  Discretisation discretisation = Discretisation::kTustin;  ///< for domain "s": "tustin" or "zoh"
  bool allow_unstable = false;  ///< accept an unstable C or T (beyond one integrator)
  double saturation_mm = 0.0;   ///< |u| <= saturation_mm [mm]; 0: no limit
  double rate_limit_mm_s = 0.0; ///< |u_k - u_{k-1}| <= rate_limit_mm_s dt [mm/s]; 0: no limit
  bool operator==(const LtiConfig&) const = default;
};

/// Where an adaptive compensator takes the target's derivatives x_t', x_t'', x_t''' from.
enum class TargetDerivatives { kIntegrator, kDifference };
inline constexpr std::array<Named<TargetDerivatives>, 2> kTargetDerivativesNames = {
    {{TargetDerivatives::kIntegrator, "integrator"}, {TargetDerivatives::kDifference, "difference"}}};

/// `ats`: the adaptive time-series compensator (Chae, Kazemibidokhti & Ricles, Earthquake Engng
/// Struct. Dyn. 42(11) 2013), with the defaults of OpenFresco's set-up of it
/// (EXAMPLES/OneBayFrame/ControlSystem/ATS_setup.m; docs/controllers.md):
///   u_k = a0 x_t + a1 x_t' + a2 x_t''   (x_t = r, the target) [mm],
/// a = [a0 [-], a1 [s], a2 [s^2]] re-estimated every step by least squares of the filtered command
/// on the filtered measured displacement and its backward differences over a sliding window.
struct AtsConfig {
  std::array<double, 3> initial{1.0, 0.020, 2.0e-4};  ///< a at start (OpenFresco Par: 1, 20 ms, (20 ms)^2 / 2)
  std::array<double, 3> lower{0.7, 0.0, 0.0};         ///< bounds (P_range) [-, s, s^2]
  std::array<double, 3> upper{1.3, 0.08, 0.0032};
  /// Largest change per second [1/s, s/s, s^2/s]: OpenFresco's MRC = [2, 0.05, 0.001] per sample
  /// at its 1024 Hz, i.e. [2048, 51.2, 1.024] per second.
  std::array<double, 3> max_rate_per_s{2048.0, 51.2, 1.024};
  double window_s = 1.0;        ///< least-squares window (tl) [s]
  int skip = 16;                ///< every skip-th sample of the window enters the regression (SN)
  double filter_hz = 20.0;      ///< Butterworth low-pass on u and y before the regression [Hz]
  int filter_order = 6;         ///< its order (analog prototype, discretised by ZOH as OpenFresco)
  double threshold_mm = 0.254;  ///< adaptation starts once |filtered y| exceeds it (0.01 in) [mm]
  /// x_t', x_t'': "integrator" (r', r'' of Eqs. 20-22, as OpenFresco uses its predictor's target
  /// velocity and acceleration) or "difference" (backward differences of r).
  TargetDerivatives derivatives = TargetDerivatives::kIntegrator;
  bool operator==(const AtsConfig&) const = default;
};

/// Where `ambc` starts: the inverse of controller.model (the coefficients of Eq. 19) or `initial`.
enum class AmbcStart { kModel, kGiven };
inline constexpr std::array<Named<AmbcStart>, 2> kAmbcStartNames = {
    {{AmbcStart::kModel, "model"}, {AmbcStart::kGiven, "given"}}};

/// `ambc`: adaptive model-based compensation (Fermandois, Mech. Syst. Signal Process. 2019; the
/// robust version of Galmez & Fermandois, Struct. Control Health Monit. 2022, public code
/// FermandoisLab/RobustAMBCvRTHS; docs/controllers.md): the inverse of a third-order model,
///   u_k = a0 x_t + a1 x_t' + a2 x_t'' + a3 x_t'''  [mm],
/// a = [a0 [-], a1 [s], a2 [s^2], a3 [s^3]] adapted by the normalised gradient law on the filtered
/// command and measured displacement (computed in metres, as published: the gains are SI).
struct AmbcConfig {
  AmbcStart start = AmbcStart::kModel;  ///< "model": a = Eq. 19's (a0..a3) of controller.model
  /// a at start for start = "given": RobustAMBCvRTHS's actuator without specimen.
  std::array<double, 4> initial{1.000000015, 0.0198592, 8.44014e-5, 1.98592e-7};
  std::array<double, 4> gain_log10{8.4, 6.2, 2.1, 0.8};  ///< Gamma = diag(10^g) (SI; RobustAMBCvRTHS's calibration)
  std::array<double, 4> lower{0.0, 0.0, 0.0, 0.0};       ///< bounds on the coefficients used [-, s, s^2, s^3]
  std::array<double, 4> upper{1e6, 1e6, 1e6, 1e6};       ///< (none in RobustAMBCvRTHS: a_i >= 0 only)
  double filter_hz = 20.0;  ///< digital Butterworth low-pass on u and y before the law [Hz]
  int filter_order = 4;
  /// x_t', x_t'', x_t''': "difference" (backward differences of r, as RobustAMBCvRTHS) or
  /// "integrator" (r', r'', r''' of Eqs. 20-22).
  TargetDerivatives derivatives = TargetDerivatives::kDifference;
  bool operator==(const AmbcConfig&) const = default;
};

/// The outer-loop controllers (ControllerConfig::kind): Table 1 of the paper, then the others.
enum class ControllerKind { kNone, kFf, kPoly3, kLead, kFfLp, kBumplessLp, kFfLqg, kLti, kAts, kAmbc };
inline constexpr std::array<Named<ControllerKind>, 10> kControllerKindNames = {
    {{ControllerKind::kNone, "none"},
     {ControllerKind::kFf, "ff"},
     {ControllerKind::kPoly3, "poly3"},
     {ControllerKind::kLead, "lead"},
     {ControllerKind::kFfLp, "ff_lp"},
     {ControllerKind::kBumplessLp, "bumpless_lp"},
     {ControllerKind::kFfLqg, "ff_lqg"},
     {ControllerKind::kLti, "lti"},
     {ControllerKind::kAts, "ats"},
     {ControllerKind::kAmbc, "ambc"}}};

/// Outer-loop tracking controller (procs/controller); Table 1 of the paper.
struct ControllerConfig {
  /// "none" (u = r) | "ff" (model inverse, Eqs. 16-22) | "poly3" (third-order polynomial
  /// extrapolation, Horiuchi 1996) | "lead" (single-pole single-zero lead compensator) |
  /// "ff_lp" (model inverse with a Butterworth low-pass, Carrion & Spencer 2007) |
  /// "bumpless_lp" (ff_lp for model_low and model_high blended by damper current) |
  /// "ff_lqg" (ff with `model` plus LQG feedback designed on `model`, Eqs. 23-27) |
  /// "lti" (u = C (T r - y) from transfer functions, `lti`) | "ats" (adaptive time series, `ats`) |
  /// "ambc" (adaptive model-based compensation, `ambc`).
  ControllerKind kind = ControllerKind::kFf;
  models::ServoModel3 model{};         ///< design model for "ff", "ff_lp", "ff_lqg"
  /// docs/models.md section 2: evaluate the feedforward half a step ahead to cancel the ZOH's
  /// half-sample lag in simulation. false = the paper's Eq. 19.
  bool half_step_ahead = false;
  double delay_ms = 9.0;        ///< "poly3", "lead": the delay compensated [ms], (0, max_delay_ms]
  double max_delay_ms = 15.0;   ///< bound on delay_ms (extrapolation amplifies noise), (0, 100]
  double lead_tp_ms = 0.5;      ///< "lead": pole time constant T_p [ms] (T_z = delay + T_p), (0, 100]
  double lp_cutoff_hz = 318.0;  ///< "ff_lp", "bumpless_lp": Butterworth cutoff [Hz], (0, 0.5/dt)
  int lp_order = 3;             ///< Butterworth order, [3, 8] (the inverse is improper by 3)
  models::ServoModel3 model_low{1.730e7, 182.7, 225.3, 9.499e4, "0.0A"};   ///< "bumpless_lp": at 0 A (Eq. 28)
  models::ServoModel3 model_high{1.613e7, 134.2, 324.6, 1.211e5, "2.5A"};  ///< at current_high_A (Eq. 29)
  double current_high_A = 2.5;  ///< "bumpless_lp": lambda = i_eff / current_high_A, (0, 5]
  LqgConfig lqg{};              ///< "ff_lqg"
  LtiConfig lti{};              ///< "lti"
  AtsConfig ats{};              ///< "ats"
  AmbcConfig ambc{};            ///< "ambc" (start = "model" uses `model`)
  bool operator==(const ControllerConfig&) const = default;
};

}  // namespace rths::control
