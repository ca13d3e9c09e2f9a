#pragma once
/// @file The MR damper's current dynamics (paper Eq. 40 and its 75 Hz low-pass; docs/models.md
/// section 6): the commanded current i_d [A] becomes the effective current i_c [A] that enters
/// Eqs. 35-39,
///
///     i_c(s) = H(s) i_d(s),   H(s) = (s + 9 pi) / (9 (s + pi))  *  w_n^2 / (s^2 + 2 zeta w_n s + w_n^2)
///              \______ Eq. 40: PWM driver + field lag ______/    \__ 2nd-order Butterworth __/
///
/// with w_n = 2 pi 75 rad/s and zeta = 1/sqrt(2) (0.707; the paper gives no damping). H(0) = 1,
/// H is strictly proper (i_c is continuous), and Eq. 40 alone jumps by 1/9 of a step at once.
/// In general Eq. 40 is (a / b) (s + b) / (s + a) with a = pi, b = 9 pi (DC gain 1, jump a / b).
///
/// Realisation: modal (real Jordan) form of H, which is also an exact ZOH discretisation.
/// The poles are lambda_1 = -a (Eq. 40's own state) and lambda = -zeta w_n + j w_n sqrt(1 - zeta^2)
/// (the low-pass pair). With LP(s) the low-pass, residues r_1 = a (1 - a / b) LP(-a) and
/// r = (a / b) (lambda + b) / (lambda + a) w_n^2 / (lambda - conj(lambda)),
///
///     m_1' = -a m_1 + i_d,     q' = lambda q + i_d (q complex: two real states),
///     i_c  = r_1 m_1 + 2 Re(r q),      Eq. 40's output alone: i_40 = (a/b) i_d + a (1 - a/b) m_1.
///
/// The state is stored as its deviation from the steady state of the held command i_h:
/// e_1 = m_1 - i_h / a, e_q = q + i_h / lambda. Then, with i_d = i_h held over a step,
///
///     e(t_k + tau) = e^{lambda tau} e(t_k)   (each mode on its own),
///     i_c(t_k + tau) = i_h + r_1 e_1 e^{-a tau} + 2 Re(r e_q e^{lambda tau}),
///
/// which is the exact ZOH solution x_{k+1} = Phi x_k + Gamma i_k of the realisation
/// (x = e + x_ss(i_h), Gamma = (I - Phi) x_ss(1)). A new command i_k re-expresses the deviation
/// (Hold(): e_1 -= (i_k - i_h) / a, e_q += (i_k - i_h) / lambda), which leaves i_c continuous.
/// At steady state e = 0 exactly, so a constant current stays exactly constant (bit for bit),
/// and the within-step closed form lets a damper ODE use i_c(t) as a continuous function of time
/// without carrying the filter in the ODE's state.
#include <array>
#include <complex>

#include "core/names.h"

namespace rths::models {

/// The form of H(s) (CurrentDriverParams::kind).
///  - kEq40: the paper's Eq. 40 times the second-order low-pass (file comment);
///  - kFirstOrder: the control-input filter of Spencer et al. (1997), u' = -eta (u - v), i.e.
///    H(s) = eta / (s + eta): one real mode, pole -eta, residue eta (the complex pair has
///    residue 0). The command v may be a current [A] or a voltage [V]; u has the same unit.
enum class CurrentFilter { kEq40, kFirstOrder };
inline constexpr std::array<Named<CurrentFilter>, 2> kCurrentFilterNames = {
    {{CurrentFilter::kEq40, "eq40"}, {CurrentFilter::kFirstOrder, "first_order"}}};

/// The driver's state when a test starts (CurrentDriverParams::start, `[plant.current_driver] start`):
///  - kSteady: at the steady state of the first command, as if it had been held before the test
///    (the current is set before the test starts; the default);
///  - kRest: at rest at 0 A, as an amplifier switched on with the test: a first command that is not
///    0 starts a transient (Eq. 40: 1 / a = 0.32 s).
enum class CurrentStart { kSteady, kRest };
inline constexpr std::array<Named<CurrentStart>, 2> kCurrentStartNames = {
    {{CurrentStart::kSteady, "steady"}, {CurrentStart::kRest, "rest"}}};

/// Parameters of H(s). Defaults: the paper's Eq. 40 and a 75 Hz Butterworth.
struct CurrentDriverParams {
  CurrentFilter kind = CurrentFilter::kEq40;  ///< `[plant.current_driver] kind`
  double eta_1_s = 190.0;  ///< kFirstOrder: eta [1/s], > 0 (Spencer et al. 1997 fitted 190 1/s)
  double lag_pole_rad_s = 3.141592653589793;   ///< Eq. 40's pole a = pi [rad/s], > 0
  double lag_zero_rad_s = 28.274333882308138;  ///< Eq. 40's zero b = 9 pi [rad/s], > 0
  double lowpass_hz = 75.0;                   ///< low-pass natural frequency w_n / 2 pi [Hz], > 0
  double lowpass_zeta = 0.7071067811865476;   ///< low-pass damping, (0, 1) (1/sqrt(2): Butterworth)
  CurrentStart start = CurrentStart::kSteady;  ///< the state at the test's start (CurrentStart)
  bool operator==(const CurrentDriverParams&) const = default;
};

/// Immutable description: modal coefficients and the per-step transition factors.
struct CurrentDriver {
  CurrentDriverParams params;
  double dt_s = 0.0;              ///< step [s]
  double pole1 = 0.0;             ///< lambda_1 = -a [1/s]
  std::complex<double> pole;      ///< lambda of the low-pass pair [1/s] (upper half plane)
  double residue1 = 0.0;          ///< r_1 [1/s]
  std::complex<double> residue;   ///< r [1/s]
  double phi1 = 0.0;              ///< e^{lambda_1 dt}
  std::complex<double> phi;       ///< e^{lambda dt}

  /// Throws rths::Error naming a bad parameter (kEq40: 0 < a, a != b, b > 0, 0 < lowpass_hz,
  /// zeta in (0, 1); kFirstOrder: eta_1_s > 0; dt_s > 0, all finite).
  static CurrentDriver Make(const CurrentDriverParams& p, double dt_s);
  /// H(j 2 pi f_hz) (continuous, [A/A]).
  std::complex<double> FrequencyResponse(double f_hz) const;
  /// H(0) from the modal form, sum r_j / (-lambda_j): 1 up to rounding.
  double DcGain() const;
};

/// Per-step state: the held command and the modal deviation from its steady state.
struct CurrentDriverState {
  double held_A = 0.0;                   ///< i_h: command held over the current step [A]
  double e1_A_s = 0.0;                   ///< e_1 = m_1 - i_h / a [A s]
  std::complex<double> eq_A_s{0.0, 0.0}; ///< e_q = q + i_h / lambda [A s]
};

/// The steady state for a constant current i_A [A] (held for ever): i_c = i_A exactly.
CurrentDriverState SteadyState(double i_A);
/// The state before a test's first step whose first command is i_first_A [A]: SteadyState(i_first_A)
/// for CurrentStart::kSteady, SteadyState(0) for kRest.
CurrentDriverState StartState(const CurrentDriverParams& p, double i_first_A);
/// true when the state is exactly at the steady state of its held command (e = 0): i_c(t) = i_h
/// for as long as the command stays i_h.
bool AtSteadyState(const CurrentDriverState& s);

/// Start of step k: the command i_cmd_A [A] is held from t_k on. Re-expresses the deviation for
/// the new hold; i_c(t_k) is unchanged (continuous). Allocates nothing.
void Hold(const CurrentDriver& d, CurrentDriverState* s, double i_cmd_A);
/// Effective current i_c(t_k + tau_s) [A] within the step that Hold() started, tau_s >= 0 [s]
/// (closed form; exact for any tau_s while the command is held).
double EffectiveCurrentAt(const CurrentDriver& d, const CurrentDriverState& s, double tau_s);
/// A deviation contributing less than this to i_c [A] counts as settled (Advance() zeroes it).
inline constexpr double kSettledA = 1e-15;

/// End of the step: the state at t_{k+1} = t_k + dt (e <- e^{lambda dt} e; a deviation whose
/// contribution to i_c is below kSettledA is set to exactly 0). Allocates nothing.
void Advance(const CurrentDriver& d, CurrentDriverState* s);
/// Hold(i_cmd_A) then Advance(): one ZOH step [t_k, t_{k+1}).
void Step(const CurrentDriver& d, CurrentDriverState* s, double i_cmd_A);

/// Effective current at the sample, i_c(t_k) [A].
double EffectiveCurrentA(const CurrentDriver& d, const CurrentDriverState& s);
/// Output of Eq. 40 alone (before the low-pass) at the sample [A]: i_h + a (1 - a / b) e_1
/// (= i_h + (8 pi / 9) e_1 for the paper's a = pi, b = 9 pi).
double DriverOutputA(const CurrentDriver& d, const CurrentDriverState& s);

}  // namespace rths::models
