#pragma once
/// @file The critical delay of a real-time hybrid simulation (docs/reproduce_nonlinear.md): the
/// smallest pure actuator delay at which the RTHS loop of a partitioned SDOF loses stability, found
/// by simulating the loop in one process and bisecting on the delay.
///
/// The loop (sample k -> k + 1, dt the RTHS step):
///
///     r_k = the integrator's command (IntegratorState::x);     u_k = compensator(r_k)
///     y_k = u(t_k - tau): the actuator as a pure delay tau [s], u linearly interpolated between
///           its samples (u = 0 before t = 0), so tau need not be a multiple of dt
///     f_k = k_e y_k: the physical substructure, a linear spring, "measured" exactly
///     Advance(integrator, a_g,k, a_g,k+1, f_k) -> r_{k+1}
///
/// The partition (SplitSdof): the SDOF of mass m, initial stiffness k = m (2 pi f)^2 and viscous
/// damping c = 2 zeta m (2 pi f) is split into a numerical substructure (m, c and a story spring of
/// initial stiffness (1 - rho) k, linear or hysteretic) and a physical one (a linear spring
/// k_e = rho k). Delay-free, the loop is the SDOF itself.
///
/// Stability of one run (Unstable), by one of two criteria (DelayCriterion). After the record the
/// ground is held at zero for a free-vibration tail.
///  - decay (the default): the run is unstable if its command leaves finite numbers or a bound (a
///    multiple of the delay-free run's peak), or if the oscillation does not decay in the tail: the
///    range (max - min) of r over the tail's last quarter is at least decay_ratio (0.999) times the
///    range over its second quarter. For a linear loop this is the sign of the growth rate of its
///    least damped mode, the quantity whose zero the closed-form delay margin gives
///    (ContinuousDelayMargin); 0.999 over 10 s moves it by a growth rate of 1e-4 /s (0.4 us of
///    delay for the reference SDOF). With a hysteretic spring it also catches a self-sustained
///    oscillation (a limit cycle: the range repeats), and the range ignores the residual drift the
///    tail oscillates about.
///  - divergence: unstable only if r leaves finite numbers or the bound within record and tail.
///
/// The search (FindCriticalDelay): delays from 0 upward (steps growing with the delay) until the
/// first unstable one, then bisection between it and the last stable one down to a resolution.
/// The result is the first loss of stability met going up from 0: a stable window at larger
/// delays (possible with compensation) is not looked for.
#include <array>
#include <string>
#include <vector>

#include "core/names.h"
#include "models/integrator_config.h"
#include "models/nonlinear_building.h"
#include "models/servo_linear.h"
#include "models/story_spring.h"

namespace rths::studies {

/// A SDOF split into a numerical substructure and a linear physical spring (see @file).
struct SplitSdof {
  double mass_kg = 20000.0;        ///< m [kg]
  double frequency_hz = 5.0;       ///< natural frequency at the total initial stiffness k [Hz]
  double damping_ratio = 0.02;     ///< viscous, of critical at k; all of it numerical [-]
  double physical_fraction = 0.5;  ///< rho: k_e = rho k, (0, 1)
  /// The numerical story spring's law (linear, bouc_wen, bilinear); its k_kN_per_mm is replaced by
  /// (1 - rho) k. A bilinear spring's f_y_kN is taken as given.
  models::SpringParams spring{};

  double Mass_kN_s2_per_mm() const { return mass_kg * 1e-6; }
  double TotalStiffness_kN_per_mm() const;     ///< k = m (2 pi f)^2
  double Damping_kN_s_per_mm() const;          ///< c = 2 zeta m (2 pi f)
  double PhysicalStiffness_kN_per_mm() const { return physical_fraction * TotalStiffness_kN_per_mm(); }
  double NumericalStiffness_kN_per_mm() const { return (1.0 - physical_fraction) * TotalStiffness_kN_per_mm(); }
  /// Throws rths::Error naming the field unless m, f > 0, zeta in [0, 1), rho in (0, 1).
  void Validate() const;
};

/// The numerical substructure of s: m, c, the spring at (1 - rho) k, the physical spring's force
/// on the one DOF (specimen count 1).
models::NonlinearBuilding NumericalSubstructure(const SplitSdof& s);

/// What compensates the delay (the tracking controller), designed for the delay tau it faces.
enum class DelayCompensation {
  kNone,   ///< u = r
  kPoly3,  ///< control::PolynomialExtrapolation over tau (Horiuchi et al. 1996)
  kLead,   ///< control::LeadCompensator over tau, T_p = kDelayLeadTpS (Table 1's `lead`)
  kFf,     ///< control::ModelFeedforward on TaylorDelayModel(tau): the same commands as kPoly3
};
inline constexpr std::array<Named<DelayCompensation>, 4> kDelayCompensationNames = {
    {{DelayCompensation::kNone, "none"},
     {DelayCompensation::kPoly3, "poly3"},
     {DelayCompensation::kLead, "lead"},
     {DelayCompensation::kFf, "ff"}}};
/// The lead compensator's pole time constant T_p [s] (controller.lead_tp_ms's default, 0.5 ms).
inline constexpr double kDelayLeadTpS = 0.5e-3;

/// The pure delay e^{-s tau} as the third-order model ff inverts: K / ((s + p)(s^2 + b s + c)) with
/// (s + p)(s^2 + b s + c) / K = 1 + tau s + (tau s)^2 / 2 + (tau s)^3 / 6, the Taylor series of
/// e^{s tau} to third order (all its roots in the left half plane): p = 1.5961 / tau,
/// b = 3 / tau - p, c = 6 / (tau^3 p), K = 6 / tau^3. Throws rths::Error unless tau_s > 0.
models::ServoModel3 TaylorDelayModel(double tau_s);

/// One loop: structure, integrator, record, compensation.
struct DelayLoop {
  SplitSdof sdof;
  models::IntegratorConfig integrator{};
  double dt_s = 0.0005;                 ///< RTHS step [s]
  std::vector<double> ground_mm_s2;     ///< a_g at k dt [mm/s^2]: the record
  double tail_s = 20.0;                 ///< free vibration after the record [s], > 0
  DelayCompensation compensation = DelayCompensation::kNone;
};

/// What one run of the loop gave.
struct DelayRun {
  bool diverged = false;          ///< r left finite numbers or |r| exceeded the bound
  double peak_mm = 0.0;           ///< max |r| over the run (to the stop if diverged) [mm]
  double tail_early_range_mm = 0; ///< max r - min r over the tail's second quarter [mm]
  double tail_late_range_mm = 0;  ///< the same over its last quarter [mm]
  double peak_ductility = 0.0;    ///< max |drift| / yield displacement of the spring (0 if linear)
  long steps = 0;                 ///< steps run
};

/// Runs `loop` with the actuator delay tau_s [s] (>= 0), stopping as soon as |r| > bound_mm
/// (bound_mm <= 0: no bound). Throws rths::Error for tau_s < 0 or an integrator it cannot make.
DelayRun RunDelayLoop(const DelayLoop& loop, double tau_s, double bound_mm);

/// What makes a run unstable (see @file).
enum class DelayCriterion { kDecay, kDivergence };

/// How FindCriticalDelay searches and judges.
struct DelaySearch {
  DelayCriterion criterion = DelayCriterion::kDecay;
  double decay_ratio = 0.999;         ///< kDecay: the tail must shrink below this ratio [-]
  double resolution_s = 1e-5;         ///< bisection stops at this bracket width [s]
  double scan_step_s = 0.25e-3;       ///< smallest scan step [s]
  double scan_growth = 0.1;           ///< scan step at least this fraction of the delay [-]
  double max_delay_s = 0.1;           ///< no instability up to here: reported as not found [s]
  double divergence_factor = 10.0;    ///< bound = this x the delay-free run's peak [-]
};

/// The stability verdict of a run by search.criterion (see @file).
bool Unstable(const DelayRun& r, const DelaySearch& search);
/// "diverged", "does not decay" or "decays" (kDecay's tail test, whatever the criterion).
std::string Verdict(const DelayRun& r, const DelaySearch& search);

struct CriticalDelay {
  bool found = false;             ///< an unstable delay was met at or below max_delay_s
  double tau_s = 0.0;             ///< the bracket's midpoint [s] (found), else max_delay_s
  double stable_s = 0.0;          ///< the largest delay run and found stable [s]
  double unstable_s = 0.0;        ///< the smallest delay run and found unstable [s] (found)
  std::string verdict;            ///< Verdict of the run at unstable_s
  double delay_free_peak_mm = 0;  ///< peak |r| without delay [mm]
  double delay_free_ductility = 0;///< peak ductility without delay (0 if linear)
  int runs = 0;                   ///< loop runs the search made
};

/// The critical delay of `loop` (see @file). Throws rths::Error if the delay-free loop is unstable.
CriticalDelay FindCriticalDelay(const DelayLoop& loop, const DelaySearch& search);

/// The delay margin of the continuous loop, linear and uncompensated:
///     m x'' + c x' + k_n x + k_e x(t - tau) = 0                (a delay differential equation)
/// exact: the smallest tau at which a root of m s^2 + c s + k_n + k_e e^{-s tau} = 0 reaches the
/// imaginary axis s = i w, i.e. |k_n - m w^2 + i c w| = k_e and
/// w tau = pi - arg(k_n - m w^2 + i c w) (mod 2 pi) (Wallace et al. 2005, EESD 34(15); the
/// method of Chen & Ricles 2008, EESD 37(4), in continuous time); and the negative-damping estimate
/// of Horiuchi et al. (1999, EESD 28(10)): k_e x(t - tau) ~ k_e x - k_e tau x', unstable once
/// k_e tau > c, tau ~ c / k_e.
struct DelayMargin {
  bool exists = false;           ///< false: stable for every delay (k_e below the numerical part's gain)
  double tau_s = 0.0;            ///< the exact margin [s]
  double crossing_hz = 0.0;      ///< the frequency at which the root crosses [Hz]
  double negative_damping_s = 0; ///< c / k_e [s]
};
/// m [kN s^2/mm], c [kN s/mm], k_n, k_e [kN/mm]; all >= 0, m > 0.
DelayMargin ContinuousDelayMargin(double m, double c, double k_n, double k_e);

}  // namespace rths::studies
