#pragma once
/// @file `ats`: the adaptive time-series compensator (Y. Chae, K. Kazemibidokhti, J. M. Ricles,
/// "Adaptive time series compensator for delay compensation of servo-hydraulic actuator systems
/// for real-time hybrid simulation", Earthquake Engng Struct. Dyn. 42(11):1697-1715, 2013), as
/// OpenFresco runs it (EXAMPLES/OneBayFrame/ControlSystem/ATS_setup.m and HybridControllerD2D2.slx;
/// docs/controllers.md). Signals in mm, time in s.
///
/// Command (target x_t = r):
///   u_k = a0 x_t,k + a1 x_t',k + a2 x_t'',k                                       [mm]
/// with x_t', x_t'' the integrator's r'_k, r''_k (Eqs. 20-22; "integrator") or the backward
/// differences (r_k - r_{k-1})/dt and (r_k - 2 r_{k-1} + r_{k-2})/dt^2 ("difference"), r = 0 before
/// the first step. For a plant y(t) = A u(t - tau), u(t) = x_t(t + tau)/A ~ (1/A)(x_t + tau x_t' +
/// tau^2/2 x_t''): a0 = 1/A [-], a1 ~ tau/A [s], a2 ~ tau^2/(2A) [s^2].
///
/// Estimation, every step k (OpenFresco's order of operations):
///   uf = F(u), yf = F(y): the same Butterworth low-pass F on the compensator's own commands and
///     on the measured displacement; F is strictly proper, so uf_k, yf_k use u, y up to k-1;
///   D1_k = (yf_k - yf_{k-1})/dt,  D2_k = (D1_k - D1_{k-1})/dt  (Simulink Discrete Derivatives);
///   the window: samples j = k-N, k-N+skip, ... < k of (uf, yf, D1, D2), N = round(window_s/dt)
///     (a tapped delay that excludes the current sample and holds zeros before the first step);
///   least squares  min_a sum_j (uf_j - a0 yf_j - a1 D1_j - a2 D2_j)^2  by its 3x3 normal equations
///     (the inverse model: command from response; identical filters on both sides cancel);
///   trigger: no estimation until |yf_k| > threshold_mm, then on for good; before it a = initial;
///   a solve that is not finite gives the initial values (so does a numerically singular one:
///     the normal matrix scaled to unit diagonal with a reciprocal condition below 1e-13); then
///   |a_i,k - a_i,k-1| <= max_rate_per_s_i dt; then lower_i <= a_i,k <= upper_i.
/// u_k uses a_k, estimated from the window up to k-1: y_k itself only enters the filter state for
/// the next step (so u_k does not depend on y_k).
///
/// The filter: the analog Butterworth prototype of order n at w_c = 2 pi filter_hz, unity DC gain,
/// discretised by a zero-order hold at dt (MATLAB's c2d(tf(butter(n, w_c, 's')), dt), as
/// ATS_setup.m). It is realised here as the ZOH discretisation of a cascade of first- and
/// second-order analog sections in state space (exp of the augmented matrix), not as the expanded
/// z-domain polynomial: the same transfer function, but well conditioned when w_c dt is small (the
/// expanded sixth-order denominator at 4096 Hz has its six roots about 0.03 from z = 1).
#include <array>
#include <complex>
#include <vector>

#include "control/tracking_controller.h"

namespace rths::control {

/// Largest order of the low-pass filters of the adaptive controllers (fixed-size state).
inline constexpr int kMaxAdaptiveFilterOrder = 8;

/// A ZOH-discretised analog Butterworth low-pass (strictly proper):
///   x_{k+1} = Phi x_k + Gamma v_k,  w_k = C x_k.
/// Continuous realisation (states scaled by w_c): per pair s^2 + 2 sin(theta) w_c s + w_c^2,
///   x1' = w_c x2,  x2' = -w_c x1 - 2 sin(theta) w_c x2 + w_c v,  output x1;
/// for the real pole (odd order) x' = -w_c x + w_c v; the sections in series, each with unit DC gain.
struct ZohButterworth {
  int order = 0;
  double cutoff_hz = 0.0;
  double dt_s = 0.0;
  std::array<double, kMaxAdaptiveFilterOrder * kMaxAdaptiveFilterOrder> phi{};  ///< row-major
  std::array<double, kMaxAdaptiveFilterOrder> gamma{};
  std::array<double, kMaxAdaptiveFilterOrder> c{};
  /// H(e^{j 2 pi f dt}) = C (zI - Phi)^-1 Gamma (for checks).
  std::complex<double> Response(double f_hz) const;
};

/// Requires 1 <= order <= kMaxAdaptiveFilterOrder, 0 < cutoff_hz < 0.5/dt_s, dt_s > 0 (not checked
/// here: MakeAtsDesign checks them with the scenario keys).
ZohButterworth MakeZohButterworth(int order, double cutoff_hz, double dt_s);

/// The state x of a ZohButterworth (at rest: zeros).
struct ZohFilterState {
  std::array<double, kMaxAdaptiveFilterOrder> x{};
};
/// w_k = C x_k (depends on inputs up to k-1).
double ZohFilterOutput(const ZohButterworth& f, const ZohFilterState& s);
/// x_{k+1} = Phi x_k + Gamma v_k. Allocates nothing.
void ZohFilterUpdate(const ZohButterworth& f, ZohFilterState* s, double v_k);

/// The immutable design of an `ats` controller.
struct AtsDesign {
  AtsConfig config;
  double dt_s = 0.0;
  int window_samples = 0;  ///< N = round(window_s / dt)
  int points = 0;          ///< regression points per window: ceil(N / skip) (>= 3)
  std::array<double, 3> max_step{};  ///< max_rate_per_s * dt: the largest change per step [-, s, s^2]
  ZohButterworth filter;             ///< F, on u and y
};

/// Checks `cfg` and designs at dt_s. Throws rths::Error naming the scenario key, with the allowed
/// range: "run.dt_s"; "controller.ats.lower" (not finite, or above `upper`), ".upper" (not finite),
/// ".initial" (not finite or outside [lower, upper]), ".max_rate_per_s" (not > 0), ".window_s"
/// (not in (0, 100] s, more than 2^22 samples, or fewer than 3 regression points:
/// ceil(round(window_s/dt)/skip) < 3),
/// ".skip" (< 1), ".filter_order" (not in [1, 8]), ".filter_hz" (not in (0, 0.5/dt)),
/// ".threshold_mm" (not finite and >= 0).
AtsDesign MakeAtsDesign(const AtsConfig& cfg, double dt_s);

/// One sample of the regression window: F(y) [mm], its differences [mm/s, mm/s^2], F(u) [mm].
struct AtsSample {
  double yf_mm = 0.0;
  double d1_mm_s = 0.0;
  double d2_mm_s2 = 0.0;
  double uf_mm = 0.0;
};

/// The per-step state of an `ats` controller.
struct AtsState {
  ZohFilterState filter_y;   ///< F on y (after y_{k-1})
  ZohFilterState filter_u;   ///< F on u (after u_{k-1})
  double yf_mm = 0.0;        ///< yf_k of the last step (the trigger's signal) [mm]
  double d1_mm_s = 0.0;      ///< D1_k of the last step [mm/s]
  std::vector<AtsSample> window;  ///< ring of the last N samples (size N from AtsAtRest, never resized)
  int head = 0;              ///< the slot of the oldest sample, k-N (the next one written)
  bool triggered = false;    ///< the threshold was exceeded: estimating
  bool fallback = false;     ///< the last solve was not finite or singular (initial values used)
  std::array<double, 3> a{};  ///< a_k, used for u_k [-, s, s^2]
  double r1_mm = 0.0, r2_mm = 0.0;  ///< r_{k-1}, r_{k-2} ("difference") [mm]
  double u_mm = 0.0;         ///< u_k of the last AtsCommand [mm]
};

/// The state at rest (no motion before the first step; a = initial). Allocates the window once.
AtsState AtsAtRest(const AtsDesign& d);

/// First half of step k: the filtered samples at k, the window, the trigger and the estimate a_k,
/// then u_k (kept in s->u_mm). Uses no measurement of step k. Allocates nothing.
Command AtsCommand(const AtsDesign& d, AtsState* s, const Derivatives& target);
/// Second half of step k: y_k and u_k (s->u_mm) into the filters' states. Allocates nothing.
void AtsUpdate(const AtsDesign& d, AtsState* s, double y_mm);

/// F(z) of u = a0 x_t + a1 x_t' + a2 x_t'' for fixed a: with "difference", the FIR on r_k..r_{k-2}
///   h = [a0 + a1/dt + a2/dt^2, -a1/dt - 2 a2/dt^2, a2/dt^2];
/// with "integrator", FeedforwardFir of (a0, a1, a2, 0) (Eqs. 20-22 folded in).
DiscreteSs AdaptiveFir(const std::array<double, 4>& a, TargetDerivatives derivatives, double dt_s);

/// `ats` (the recursion above).
class AtsController final : public TrackingController {
 public:
  explicit AtsController(AtsDesign design) : design_(std::move(design)), state_(AtsAtRest(design_)) {}
  Command Step(const Derivatives& d, const Measurement& m) override {
    const Command c = AtsCommand(design_, &state_, d);
    AtsUpdate(design_, &state_, m.y_mm);
    return c;
  }
  /// The compensator with a fixed at `initial` (as before the trigger), no feedback.
  ControllerLti Linearize(double current_A) const override;
  const AtsDesign& design() const { return design_; }
  const AtsState& state() const { return state_; }

 private:
  const AtsDesign design_;
  AtsState state_;
};

}  // namespace rths::control
