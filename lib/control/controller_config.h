#pragma once
/// @file Configuration of the outer-loop tracking controller (procs/controller; Table 1 of the
/// paper): plain structs with defaults, filled by the scenario's [controller] table.
#include <string>

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

/// The outer-loop controllers of Table 1 (ControllerConfig::kind).
enum class ControllerKind { kNone, kFf, kPoly3, kLead, kFfLp, kBumplessLp, kFfLqg };
inline constexpr std::array<Named<ControllerKind>, 7> kControllerKindNames = {
    {{ControllerKind::kNone, "none"},
     {ControllerKind::kFf, "ff"},
     {ControllerKind::kPoly3, "poly3"},
     {ControllerKind::kLead, "lead"},
     {ControllerKind::kFfLp, "ff_lp"},
     {ControllerKind::kBumplessLp, "bumpless_lp"},
     {ControllerKind::kFfLqg, "ff_lqg"}}};

/// Outer-loop tracking controller (procs/controller); Table 1 of the paper.
struct ControllerConfig {
  /// "none" (u = r) | "ff" (model inverse, Eqs. 16-22) | "poly3" (third-order polynomial
  /// extrapolation, Horiuchi 1996) | "lead" (single-pole single-zero lead compensator) |
  /// "ff_lp" (model inverse with a Butterworth low-pass, Carrion & Spencer 2007) |
  /// "bumpless_lp" (ff_lp for model_low and model_high blended by damper current) |
  /// "ff_lqg" (ff with `model` plus LQG feedback designed on `model`, Eqs. 23-27).
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
  bool operator==(const ControllerConfig&) const = default;
};

}  // namespace rths::control
