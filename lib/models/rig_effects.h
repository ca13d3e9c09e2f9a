#pragma once
/// @file The effect library of the sim-to-real diagnosis (docs/rig_record.md, "The
/// effect library"): unmodelled effects of a real rig, as small per-sample blocks shared by the
/// plant's rig mode (procs/plant, which switches them on to rehearse a real rig) and by the
/// diagnosis (lib/diagnosis, which adds them to the nominal model to explain a residual).
/// Units: mm, kN, A, s (docs/units.md); parameters carry their unit in their name.
///
/// Where each effect acts (one order, documented in docs/diagnosis.md):
///
///   displacement path   u_k --[pure_delay]--[gain_error]--[command_dead_band (on u - x)]
///                           --> actuator model --> x_k
///                       x_k --[oil_column_resonance]--[servovalve_saturation]
///                           --[load_coupling (- c f)]--[coulomb_friction]--[presliding_friction]
///                           --[backlash]--[supply_ripple (+)]--> y_k
///   force path          i_k --[current_lag]--> model's current dynamics (Eq. 40 + 75 Hz) --> i_c
///                       damper model (Eqs. 32-39) at (y, y', i_c) --[damper_scale]
///                           --[load_cell_inertia (+ m y'')]--[channel_skew]--> f_k
///   both channels       + sensor_noise (rig mode only: the diagnosis never adds noise)
///
/// Every block is an immutable description (the parameters and dt) plus a per-step state; the
/// per-step calls allocate nothing (the delay line is sized once, at construction).
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rths::models {

/// Disturbances of the rig mode that are deliberately NOT in the effect library
/// (models/rig_effects.h), so that the diagnosis can be tested on its "unknown" verdict
/// (docs/rig_mode.md). All off (0) by default.
struct UnmodelledConfig {
  /// Periodic disturbance on the measured displacement (e.g. supply-pressure ripple):
  /// y_meas += ripple_mm sin(2 pi ripple_hz t_k). Amplitude [mm], [0, 10].
  double ripple_mm = 0.0;
  double ripple_hz = 0.0;            ///< [Hz], (0, 0.5/run.dt_s) when ripple_mm > 0, else [0, ...)
  /// Extra spring force on the measured force (e.g. an accumulator): f += k y, y the specimen
  /// displacement before noise [kN/mm], [-100, 100].
  double stiffness_kN_per_mm = 0.0;
  /// A damper force that fades over the test (the fluid heats): the damper's force is multiplied by
  /// fade_start + fade_per_s t_k, t_k = k dt from the rig's start. fade_start [0.1, 10] (1: off) ...
  double fade_start = 1.0;
  /// ... and its change per second [1/s], [-1, 1] (0: off); the product must stay in [0.05, 10].
  double fade_per_s = 0.0;
  /// The damper force's factor at t_s [s].
  double FadeAt(double t_s) const { return fade_start + fade_per_s * t_s; }
  /// true if every disturbance is off.
  bool Empty() const { return ripple_mm == 0.0 && stiffness_kN_per_mm == 0.0 && fade_start == 1.0 && fade_per_s == 0.0; }
  bool operator==(const UnmodelledConfig&) const = default;
};

/// Transport delay of the command: u_d(t) = u(t - tau), linear interpolation between samples.
struct PureDelay { double tau_ms = 0.0; bool operator==(const PureDelay&) const = default; };                          ///< [0, 100] ms
/// Static gain mismatch of the displacement path: the actuator model sees gain * u.
struct GainError { double gain = 1.0; bool operator==(const GainError&) const = default; };                            ///< [0.5, 2]
/// The actuator yields under the specimen force: y_k = x_k - compliance * f, with f the force
/// the caller couples with (Post's f_kN: the diagnosis passes the measured f_k; the rig mode the
/// true f_k of the same sample, solved per step, or f_{k-1} on request: docs/rig_mode.md).
struct LoadCoupling { double compliance_mm_per_kN = 0.0; bool operator==(const LoadCoupling&) const = default; };         ///< [-1, 1] mm/kN
/// An extra, lightly damped mode in series: w^2 / (s^2 + 2 zeta w s + w^2), w = 2 pi f_hz
/// (unity at DC), discretised exactly with a zero-order hold on its input.
struct OilColumnResonance { double f_hz = 60.0; double zeta = 0.05; bool operator==(const OilColumnResonance&) const = default; };  ///< f in (0, 0.45/dt), zeta (0, 2]
/// Seal friction: displacement lost against the direction of motion,
/// y = x - loss * tanh(x' / v_smooth), x' = (x_k - x_{k-1}) / dt of the block's input.
struct CoulombFriction { double loss_mm = 0.0; double v_smooth_mm_s = 0.5; bool operator==(const CoulombFriction&) const = default; };  ///< loss [0, 10] mm
/// Dead band (play operator): y holds until its input has moved gap/2 past it, then follows.
struct Backlash { double gap_mm = 0.0; bool operator==(const Backlash&) const = default; };                           ///< [0, 10] mm
/// Presliding (Dahl-type) friction: a lost motion z = x - y that builds up over a travel after
/// each reversal, independent of the velocity. Dahl's law (Dahl 1968, docs/rig_mode.md "Lost motion
/// at reversals") on the output's travel: dz/dy = (loss - z sgn(y')) / travel, which at a
/// reversal gives dy/dx = travel / (travel + 2 loss) (the output creeps) rising to 1 as the
/// lost motion reaches loss. travel -> 0 is backlash with gap 2 loss; a large travel is a small,
/// smooth lag. Solved exactly per sample (docs/rig_mode.md).
struct PreslidingFriction {
  double loss_mm = 0.0;    ///< the lost motion once sliding [mm], [0, 10]
  double travel_mm = 0.1;  ///< the presliding travel over which it builds up [mm], [1e-6, 100]
  bool operator==(const PreslidingFriction&) const = default;
};
/// Servovalve overlap: a dead band on the servo loop's error. The actuator model is driven by
/// x_k + dz(v_k - x_k), v_k the command after pure_delay and gain_error, x_k the actuator
/// model's output at t_k and dz(e) = sgn(e) max(0, |e| - width/2): within width/2 of its command
/// the actuator gets no flow and stops (a play inside the loop, filtered by the actuator's
/// dynamics, where backlash is a play on its output).
struct CommandDeadBand { double width_mm = 0.0; bool operator==(const CommandDeadBand&) const = default; };  ///< [0, 10] mm
/// Hydraulic supply (pump) ripple: the pump's pressure pulsation at its piston frequency f and its
/// harmonics moves the actuator at frequencies the servo loop does not follow, an additive
/// periodic motion of the specimen (the damper sees it too):
///     y_k += amplitude sum_{h=1..kRippleHarmonics} w_h sin(2 pi h f t_k + phi_h),  t_k = k dt
/// from the block's Reset, with the library's shape w = (1, 0.5, 0.25), phi = (0, 1, 2) rad. A
/// harmonic at or above the Nyquist frequency is left out (a DAQ's anti-alias filter removes it;
/// sampled, it would fold onto any frequency, down into the test's band). The diagnosis does not assume this shape: it fits the amplitude and phase
/// of every harmonic per record (a pump is not synchronised with the test; docs/diagnosis.md
/// "Supply ripple"), and reports the fundamental's amplitude.
struct SupplyRipple {
  double f_hz = 200.0;        ///< the pump's fundamental [Hz], (0, 0.5/dt)
  double amplitude_mm = 0.0;  ///< the fundamental's amplitude [mm], [0, 10]
  bool operator==(const SupplyRipple&) const = default;
};
/// Harmonics of SupplyRipple (the fundamental included).
inline constexpr int kRippleHarmonics = 3;
/// true if SupplyRipple's harmonic h (1 = the fundamental) at f_hz is below the Nyquist frequency
/// 0.5 / dt_s: the harmonics that are sampled (the others are left out).
inline bool RippleHarmonicSampled(int h, double f_hz, double dt_s) { return h * f_hz * dt_s < 0.5; }
/// The library's shape of SupplyRipple: amplitude weight and phase [rad] of harmonic h = 1, 2, 3.
inline constexpr std::array<double, kRippleHarmonics> kRippleWeights{1.0, 0.5, 0.25};
inline constexpr std::array<double, kRippleHarmonics> kRipplePhases{0.0, 1.0, 2.0};
/// Flow limit. in_loop = 0: on the actuator's output, which moves at most vmax * dt per step towards
/// its input (a rate limiter after the loop). in_loop = 1: inside the servo loop, the piston's
/// velocity limited while the loop's own velocity state winds up (models/servo_flow_limit.h: the
/// actuator model is then integrated with the limit inside it, and Post does not limit).
struct ServovalveSaturation {
  double vmax_mm_per_s = 1e9;  ///< > 0
  double in_loop = 0.0;        ///< 0 (after the loop) or 1 (inside it)
  bool InLoop() const { return in_loop >= 0.5; }
  bool operator==(const ServovalveSaturation&) const = default;
};
/// Gaussian measurement noise added to a channel (rig mode only); rms in the channel's unit.
struct SensorNoise { double rms_y_mm = 0.0; double rms_f_kN = 0.0; bool operator==(const SensorNoise&) const = default; };  ///< >= 0
/// Extra first-order lag of the damper current, 1 / (tau s + 1), exact ZOH, in series with the
/// model's own current dynamics.
struct CurrentLag { double tau_ms = 0.0; bool operator==(const CurrentLag&) const = default; };                         ///< [0, 1000] ms
/// Damper force level drift: f = scale * f_model.
struct DamperScale { double scale = 1.0; bool operator==(const DamperScale&) const = default; };                         ///< [0.1, 10]
/// A time offset between the force channel and the displacement channel of the DAQ (channels
/// sampled in turn, anti-alias filters of different delays): the force recorded at t_k is the force
/// at t_k - skew, f_meas(t_k) = f(t_k - skew) (skew > 0: the force channel lags the displacement
/// channel). Offline (the diagnosis, the blocks generator) the shift is the 4-point Lagrange
/// interpolant of the samples (ShiftedSample); the rig mode, causal, delays the force channel for
/// skew > 0 and the displacement channel (which the controller then sees late) for skew < 0.
struct ChannelSkew { double skew_ms = 0.0; bool operator==(const ChannelSkew&) const = default; };  ///< [-20, 20] ms
/// The mass between the load cell and the damper (piston rod, clevis, fixture): the load cell
/// carries the damper's force plus the force that accelerates it,
///     f_measured = f_damper + m y'' 1e-6   [kN] (m [kg], y'' [mm/s^2]).
struct LoadCellInertia { double mass_kg = 0.0; bool operator==(const LoadCellInertia&) const = default; };  ///< [0, 1e4] kg

/// Which effects are on, with their parameters. Default: none (the nominal model).
struct EffectSet {
  std::optional<PureDelay> pure_delay;
  std::optional<GainError> gain_error;
  std::optional<LoadCoupling> load_coupling;
  std::optional<OilColumnResonance> oil_column_resonance;
  std::optional<CoulombFriction> coulomb_friction;
  std::optional<Backlash> backlash;
  std::optional<PreslidingFriction> presliding_friction;
  std::optional<CommandDeadBand> command_dead_band;
  std::optional<ServovalveSaturation> servovalve_saturation;
  std::optional<SensorNoise> sensor_noise;
  std::optional<CurrentLag> current_lag;
  std::optional<DamperScale> damper_scale;
  std::optional<SupplyRipple> supply_ripple;
  std::optional<ChannelSkew> channel_skew;
  std::optional<LoadCellInertia> load_cell_inertia;

  bool Empty() const;
  /// Throws rths::Error naming the effect and parameter out of its range (ranges above) for a
  /// time step dt_s [s]; `where` prefixes the message (e.g. the scenario file and table).
  void Validate(double dt_s, std::string_view where) const;
  bool operator==(const EffectSet&) const = default;
};

/// One parameter of an effect: everything the scenario reader, the validators, the rig mode
/// and the diagnosis need to know about it, in one place.
struct EffectParam {
  std::string_view key;   ///< name in scenario files and diagnosis.json (the unit is in the name)
  /// Valid range [lo, hi] (open ends as flagged). If hi_per_dt > 0 the upper end is
  /// hi_per_dt / dt_s instead (a frequency below Nyquist).
  double lo, hi;
  bool lo_open, hi_open;
  double hi_per_dt;
  bool required;          ///< a scenario's [plant.effects.<name>] table must give it
  /// Diagnosis search range (docs/diagnosis.md "Fitting"): [search_lo, search_hi], on a grid of
  /// `grid` points (0: closed form), in log space if `log`. search_hi_per_dt > 0: the upper end
  /// is search_hi_per_dt / dt_s; search_hi_from_data: given per record (servovalve_saturation:
  /// twice the largest measured velocity). fitted = false: the diagnosis keeps the default.
  bool fitted;
  double search_lo, search_hi;
  bool log;
  int grid;
  double search_hi_per_dt;
  bool search_hi_from_data;
  /// grid < 0: a switch, 0 or 1 (valid values only those two); the diagnosis tries both and counts
  /// it as no free parameter; never "at a bound".
  /// The parameter in a set where the effect is on (nullptr if it is off).
  double* (*field)(EffectSet&);

  double Lo() const { return lo; }
  /// Upper end of the valid range at time step dt_s [s].
  double Hi(double dt_s) const { return hi_per_dt > 0.0 ? hi_per_dt / dt_s : hi; }
  /// true if v is in the valid range at dt_s (and finite).
  bool Valid(double v, double dt_s) const;
  /// "[0, 100] ms"-style description of the valid range at dt_s, for messages.
  std::string RangeText(double dt_s) const;
};

/// One effect of the library (the order of the table is the contract's).
struct EffectInfo {
  std::string_view name;      ///< exactly as in the contract (scenario tables, diagnosis.json)
  char channel;               ///< 'y': displacement path, 'f': force path, 'b': both (noise)
  bool diagnosable;           ///< the diagnosis may select it (sensor_noise: no, the floor)
  std::array<EffectParam, 2> params_storage;
  std::size_t param_count;
  void (*turn_on)(EffectSet&);       ///< switches it on with its defaults
  bool (*is_on)(const EffectSet&);

  std::span<const EffectParam> params() const { return {params_storage.data(), param_count}; }
  const EffectParam* param(std::string_view key) const;
};

/// The effect library: one entry per effect. Adding an effect is one entry here (plus its
/// struct above, its member of EffectSet and its block in the classes below).
extern const std::array<EffectInfo, 15> kEffects;
/// The entry called `name`, or nullptr.
const EffectInfo* FindEffect(std::string_view name);

/// The displacement path's effects around an actuator model (order in the file comment).
/// Use: per step k, u_act = Pre(u_k) goes into the actuator model, whose output x at t_k goes
/// through Post(x, f) to give the displacement y_k (before any noise).
class DisplacementEffects {
 public:
  /// Sizes the delay line for tau (allocates here only). Throws rths::Error for bad parameters.
  DisplacementEffects(const EffectSet& effects, double dt_s);
  /// Back to rest (all inputs and outputs 0).
  void Reset();
  /// Command u_k [mm] -> the command the actuator model holds over [t_k, t_{k+1}) [mm]
  /// (pure_delay, gain_error, then command_dead_band against the actuator output x_k given to
  /// the last Post). Call once per step, in order, after that step's Post.
  double Pre(double u_mm);
  /// Actuator model output x_k [mm] at t_k and the specimen force f_kN [kN] to couple with
  /// (LoadCoupling) -> the specimen / measured displacement y_k [mm] (oil_column_resonance,
  /// servovalve_saturation, load_coupling, coulomb_friction, presliding_friction, backlash,
  /// supply_ripple at t_k = k dt, k counting the calls since Reset). Call once per step.
  double Post(double x_mm, double f_kN);
  /// true if Pre() is the identity (no delay, gain 1, no dead band).
  bool PreIsIdentity() const;

 private:
  /// presliding_friction: the lost motion z_k [mm] after the block's input moved to x_mm.
  double PreslidingStep(double x_mm);

  EffectSet e_;
  double dt_s_ = 0.0;
  // pure delay: ring buffer of past commands
  std::vector<double> ring_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  // oil column: ZOH 2x2 state-space [q, q'] with input x
  double a11_ = 1, a12_ = 0, a21_ = 0, a22_ = 1, b1_ = 0, b2_ = 0;
  double q1_ = 0, q2_ = 0;
  double rate_out_ = 0.0;      // servovalve saturation output
  double fric_prev_in_ = 0.0;  // friction block's previous input
  double play_out_ = 0.0;      // backlash output
  double dahl_prev_in_ = 0.0;  // presliding friction's previous input
  double dahl_z_ = 0.0;        // presliding friction's lost motion [mm]
  double x_last_ = 0.0;        // the actuator output given to the last Post (command_dead_band)
  std::size_t post_k_ = 0;     // the sample index of the next Post (supply_ripple's t_k)
};

/// x_k at the fractional sample position pos (in samples, any real): the 4-point Lagrange
/// interpolant through the samples j - 1 .. j + 2, j = floor(pos), indices clamped to [0, n - 1]
/// (the record held at its ends). Exact for cubics; at 0.1 of the sample rate its error is
/// about 2e-4 of the amplitude.
double ShiftedSample(std::span<const double> x, double pos);
/// x shifted by skew_s [s] at step dt_s [s]: y_k = x(t_k - skew_s) by ShiftedSample (skew > 0: a
/// delay). skew_s = 0 returns x.
std::vector<double> ShiftSamples(std::span<const double> x, double skew_s, double dt_s);

/// The force channel's measurement in the rig mode: load_cell_inertia adds m a to the damper's
/// force (the load cell also accelerates the mass between it and the damper), channel_skew delays
/// the force channel (skew > 0) or the displacement channel (skew < 0) by |skew|, through a
/// delay line of the last samples and a 4-point Lagrange interpolant over the newest four that
/// bracket t_k - |skew| (causal). Allocates only at construction.
class MeasurementEffects {
 public:
  MeasurementEffects(const EffectSet& effects, double dt_s);
  void Reset();
  /// Sample k: the specimen's displacement y_k [mm], its acceleration a_k [mm/s^2] and the damper's
  /// force f_k [kN] (after damper_scale) -> the measured displacement and force (before noise).
  void Measure(double y_mm, double a_mm_s2, double f_kN, double* y_meas_mm, double* f_meas_kN);

 private:
  /// Pushes v into the delay line and returns its value |skew| ago (before the line holds enough
  /// samples, the oldest one stands in: the rig was at rest before its first sample).
  double Delay(double v);
  double mass_kg_ = 0.0;
  double delay_samples_ = 0.0;  // |skew| / dt
  bool delay_force_ = true;     // skew >= 0: the force channel lags, else the displacement channel
  std::vector<double> line_;    // the delayed channel's last samples, newest at head_
  std::size_t head_ = 0, count_ = 0;
};

/// The force path's effects: current_lag before the model's current dynamics, damper_scale
/// on the model's force.
class ForceEffects {
 public:
  ForceEffects(const EffectSet& effects, double dt_s);
  /// Back to rest at the constant current i0_A (the lag's state at steady state).
  void Reset(double i0_A = 0.0);
  /// Commanded current i_k [A] -> the current the model's current dynamics receive over
  /// [t_k, t_{k+1}) [A]: the lag's output, exact ZOH: l_{k+1} = a l_k + (1 - a) i_k,
  /// a = exp(-dt / tau); returns l_{k+1} (no extra sample of delay: tau -> 0 gives i_k).
  double Current(double i_A);
  /// Model force [kN] -> scale * force [kN].
  double Force(double f_kN) const;

 private:
  EffectSet e_;
  double a_ = 0.0;
  double lag_ = 0.0;
};

}  // namespace rths::models
