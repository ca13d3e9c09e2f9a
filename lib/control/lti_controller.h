#pragma once
/// @file `lti`: a tracking controller from transfer functions, as a researcher designs one in MATLAB
/// (docs/controllers.md, "A controller from transfer functions"):
///
///     u = C(z) (T(z) r - y)
///
/// with T the reference filter (feedforward) and C the feedback, both dimensionless maps of
/// displacements [mm -> mm]. Given in s (discretised at run.dt_s by Tustin or ZOH) or directly in z.
/// The RTHS benchmark's example controller (Silva et al. 2020, Eqs. 23-24) is one: C(s) = 2 + 95/s,
/// T(s) = 50.8 (s + 168.6)/(s + 8570), both by Tustin at 4096 Hz.
///
/// Step k (docs/lockstep.md): r_k = desired_t k, y_k = measured_t k (it depends on u up to k-1);
///   t_k = T(z) r_k,   e_k = t_k - y_k,   v_k = C(z) e_k   (each by FilterStep: MATLAB's `filter`),
///   u_k = v_k limited to |u_k - u_{k-1}| <= rate_limit dt, then to |u_k| <= saturation (u_{-1} = 0).
/// The limits act on the output only: C's state keeps integrating the error (no anti-windup), as a
/// Simulink Saturation block after a Discrete Transfer Fcn does.
/// The command's parts (command_t): u_fb,k = C(z) (r_k - y_k) (a second copy of C's state, run on
/// the plain error) and u_ff,k = u_k - u_fb,k, which is C (T - 1) r while no limit acts.
#include "control/tracking_controller.h"
#include "control/transfer_function.h"

namespace rths::control {

/// One of the two transfer functions, as given and as run.
struct LtiPart {
  bool given = false;               ///< false: the transfer function 1
  TfCoefficients coefficients;      ///< as given (domain s or z)
  std::vector<std::complex<double>> s_poles;  ///< the given continuous poles [1/s] (domain s only)
  DiscreteTf discrete;              ///< at run.dt_s, a[0] = 1
  TfStability stability;
};

/// The immutable design of an `lti` controller.
struct LtiDesign {
  LtiConfig config;
  double dt_s = 0.0;
  LtiPart feedback;   ///< C
  LtiPart reference;  ///< T
};

/// Checks and discretises `cfg` at dt_s. Throws rths::Error naming the key:
/// "controller.lti.feedback.num" / ".den" (empty, non-finite, improper, too many poles), and
/// "controller.lti.feedback" / "controller.lti.reference" for an unstable C or T without
/// allow_unstable (the message gives the pole in z and, for domain s, in s).
LtiDesign MakeLtiDesign(const LtiConfig& cfg, double dt_s);

/// The per-step state of an `lti` controller: three delay lines and the last command.
struct LtiState {
  TfFilterState reference;       ///< T
  TfFilterState feedback;        ///< C on T r - y
  TfFilterState feedback_plain;  ///< C on r - y (for the u_fb part)
  double u_prev_mm = 0.0;        ///< u_{k-1} [mm] (0 before the first step)
};

/// u_k and its parts from r_k and y_k [mm] (the recursion above). Allocates nothing.
Command LtiStep(const LtiDesign& d, LtiState* s, double r_mm, double y_mm);

class LtiController final : public TrackingController {
 public:
  explicit LtiController(LtiDesign design) : design_(std::move(design)) {}
  Command Step(const Derivatives& d, const Measurement& m) override { return LtiStep(design_, &state_, d.r, m.y_mm); }
  /// F = C (T - 1), C_fb = -C (ControllerLti's e = y - r): the limits left out.
  ControllerLti Linearize(double current_A) const override;
  const LtiDesign& design() const { return design_; }

 private:
  const LtiDesign design_;
  LtiState state_;
};

}  // namespace rths::control
