#pragma once
/// @file Clipped-optimal semiactive control of an MR damper (Dyke et al. 1996; docs/models.md
/// section 7; docs/semiactive.md).
///
/// Nominal controller: H2/LQG on the linear structure M x'' + C x' + K x + s f = -M iota a_g
/// (x relative to the ground, s = specimen_count e_dof, f the force of ONE damper [kN]), states
/// q = [x; x'], continuous model q' = A q + B f + E a_g:
///     A = [[0, I], [-M^-1 K, -M^-1 C]],  B = [0; -M^-1 s],  E = [0; -iota].
/// Absolute floor accelerations a = x'' + iota a_g = Ca q + Da f, Ca = [-M^-1 K, -M^-1 C],
/// Da = -M^-1 s (feedthrough from f; the ground acceleration cancels).
/// Regulated output z = [a / g ; 18 f / (18 x 200 kN)] with equal weights on every floor's
/// acceleration (in g) and a low weight r on the force (in units of the dampers' total
/// capacity): J = integral(a^T a / g^2 + r (s_sum f / F_cap)^2) dt, whose cross term a^T Da f
/// is kept. Discretised by ZOH at dt (cost integrand times dt), solved as a DARE after removing
/// the cross term.
/// Estimator: Kalman filter on the same model with the measured force as a known input, the
/// ground acceleration as white process noise of intensity `noise_ratio` times that of each
/// acceleration sensor's noise (Dyke's ratio 25: an assumption, as docs/models.md says).
/// Law: f_c = -K_lqr q_hat;  i = i_max if (f_c - f) f > 0, else 0  (H(0) = 0).
///
/// Step indices (docs/lockstep.md): at step k the freshest absolute accelerations are those of
/// sample k-1 (desired_t k: central difference knows x''_{k-1} once x_k is computed), so the
/// estimator updates with (a_{k-1}, f_{k-1}), predicts q_k, and the law compares f_c,k with the
/// force f_k measured at step k. The current it returns is held over [t_k, t_{k+1}).
#include <cstdint>

#include <Eigen/Core>

#include "core/names.h"
#include "models/structure.h"

namespace rths::control {

/// How the semiactive participant sets the damper current (SemiactiveConfig::mode).
enum class SemiactiveMode { kPassiveOff, kPassiveOn, kConstant, kPulse, kRandomPulse, kClippedOptimal };
inline constexpr std::array<Named<SemiactiveMode>, 6> kSemiactiveModeNames = {
    {{SemiactiveMode::kPassiveOff, "passive_off"},
     {SemiactiveMode::kPassiveOn, "passive_on"},
     {SemiactiveMode::kConstant, "constant"},
     {SemiactiveMode::kPulse, "pulse"},
     {SemiactiveMode::kRandomPulse, "random_pulse"},
     {SemiactiveMode::kClippedOptimal, "clipped_optimal"}}};

/// Semiactive current (procs/semiactive): constant modes, the 0.5 Hz pulse of Table 2, or
/// clipped-optimal control of the structure (docs/semiactive.md).
struct SemiactiveConfig {
  /// "passive_off" (0 A) | "passive_on" (max_current_A) | "constant" (current_A) |
  /// "pulse" (max_current_A for the first pulse_duty of every period 1/pulse_hz, then 0 A) |
  /// "random_pulse" (as "pulse", each pulse at its own level uniform in [0, max_current_A],
  /// drawn from pulse_seed: a record for identifying the current laws, Eqs. 35-39) |
  /// "clipped_optimal" (needs structure.mode = "rths").
  SemiactiveMode mode = SemiactiveMode::kPassiveOff;
  double current_A = 0.0;            ///< for "constant": [0, max_current_A]
  double max_current_A = 2.5;        ///< (0, 5]
  double pulse_hz = 0.5;             ///< "pulse": frequency [Hz], (0, 0.25/dt)
  double pulse_duty = 0.5;           ///< "pulse": fraction of the period at max current, (0, 1)
  std::uint64_t pulse_seed = 1;      ///< "random_pulse": seed of the levels
  // "clipped_optimal" (Dyke et al. 1996; docs/semiactive.md): an H2/LQG nominal controller on the
  // structure, i = max_current_A when (f_c - f) f > 0, else 0.
  double r_weight = 1e-2;            ///< weight on the force (in units of capacity), (0, 1e6]
  double noise_ratio = 25.0;         ///< ground-motion / sensor noise intensity (Dyke), (0, 1e6]
  double capacity_kN = 200.0;        ///< one damper's capacity (force unit of the cost), (0, 1e6]
  bool operator==(const SemiactiveConfig&) const = default;
};

/// Design knobs (scenario [semiactive]).
struct ClippedOptimalOptions {
  double r_weight = 1e-2;          ///< weight on the force term of J
  double noise_ratio = 25.0;       ///< ground-acceleration intensity / sensor-noise intensity
  double capacity_kN = 200.0;      ///< one damper's capacity, the force unit of J
  double max_current_A = 2.5;      ///< i_max
};

/// The designed nominal controller (immutable).
struct ClippedOptimalDesign {
  int n = 0;                  ///< structural DOFs (states 2n)
  Eigen::MatrixXd Phi, Gamma; ///< ZOH model: q_{k+1} = Phi q_k + Gamma f_k (+ noise)
  Eigen::MatrixXd Ca;         ///< absolute accelerations [mm/s^2] = Ca q + Da f
  Eigen::VectorXd Da;
  Eigen::RowVectorXd K;       ///< f_c = -K q_hat [kN per state unit]
  Eigen::MatrixXd L;          ///< Kalman gain (2n x n), current-estimator form
  Eigen::VectorXcd regulator_poles, estimator_poles;  ///< discrete, all inside the unit circle
  ClippedOptimalOptions options;
};

/// Designs the nominal LQG for `structure` at step dt_s. Throws rths::Error if a Riccati
/// equation has no stabilising solution.
ClippedOptimalDesign DesignClippedOptimal(const models::LinearStructure& structure, double dt_s,
                                          const ClippedOptimalOptions& options);

/// Per-step state of the estimator and the law.
class ClippedOptimal {
 public:
  explicit ClippedOptimal(ClippedOptimalDesign design);
  /// Step k: update with the absolute accelerations of sample k-1 [mm/s^2] and the force of
  /// one damper measured at k-1 [kN], predict sample k, and return the current command i_k [A]
  /// from the force f_k measured at k. For k = 0 (no accelerations yet) it returns 0 A.
  /// Allocates nothing.
  double Step(std::int64_t k, const double* abs_acc_prev_mm_s2, double f_prev_kN, double f_kN);
  /// Desired force of the nominal controller at the last step [kN].
  double desired_force_kN() const { return f_c_; }
  const ClippedOptimalDesign& design() const { return d_; }

 private:
  const ClippedOptimalDesign d_;
  Eigen::VectorXd q_pred_, q_post_, innovation_;
  double f_c_ = 0.0;
};

}  // namespace rths::control
