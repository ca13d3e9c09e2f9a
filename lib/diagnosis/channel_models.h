#pragma once
/// @file The nominal model of the sim-to-real diagnosis (docs/rig_record.md "Model",
/// docs/diagnosis.md) and its two channel predictors, with effects of the library
/// (models/rig_effects.h) inserted. Units: mm, kN, A, s. Offline analysis: these functions
/// allocate.
///
/// Displacement channel (from the command u and, for load_coupling, the measured force):
///     x_{k+1} = Phi x_k + Gamma Pre(u_k)        (Eq. 30 or the model file's actuator, exact ZOH)
///     yhat_k  = Post(C x_k, f_k)                (DisplacementEffects)
/// from rest at k = 0 (y_k depends on u_0 .. u_{k-1}: the record's sample pairing). The
/// load_coupling input is the MEASURED force of the same sample, f_k, not f_{k-1}: offline the
/// diagnosis has it, and a series compliance yields under the present force (the rig mode solves
/// its step for the same-sample force too, models/effect_rig.h); with f_{k-1} the residual keeps
/// c (f_k - f_{k-1}), which with a stiff damper is a fifth of the effect.
///
/// Force channel (from the MEASURED displacement y and the current command i):
///   1. y is smoothed without phase: a Butterworth low-pass of order 2 at smooth_hz run forward
///      and backward (|H|^2: a 4th-order magnitude, zero phase), the ends padded by odd
///      reflection; the velocity is the central difference of the smoothed y,
///      v_k = (ys_{k+1} - ys_{k-1}) / (2 dt) (one-sided at the ends). This keeps the noise of
///      y from being amplified (white noise sigma gives a velocity noise of about
///      2 pi sigma sqrt(smooth_hz^3 dt / 3) rms) while the motion below ~0.6 smooth_hz passes
///      unchanged in amplitude and phase.
///   2. Within a step the motion is the cubic Hermite interpolant of (ys_k, v_k), (ys_{k+1},
///      v_{k+1}) (the quintic through the accelerations too, when the motion carries them);
///      the current command i_k, through ForceEffects::Current (current_lag), is held
///      over [t_k, t_{k+1}) by Eq. 40 and the 75 Hz low-pass (models/current_driver.h, whose
///      closed form gives i_c(t) inside the step), starting at the steady state of i_0.
///   3. The Spencer damper (Eqs. 32-33) is integrated by classical Runge-Kutta (RK4) with
///      m substeps per sample, m = ceil(dt lambda / kRk4StepLambda), lambda the size of the local
///      Jacobian, (beta + gamma) n |z|^(n-1) max(|v_k|, |v_{k+1}|) + A alpha / (c0 + c1) +
///      k0 / (c0 + c1) (so h lambda <= 0.4, inside RK4's stability interval [-2.78, 0]; at 0.8
///      the saturating Bouc-Wen phase near peak velocity left 0.01-0.02 kN at 80 Hz and 2.5 A;
///      checked against the ARKODE damper at 1e-8 in tests/diagnosis/diagnosis_test.cpp). Where x' - y' changes sign
///      over the step (a reversal; its value at the end taken with the damper state at the
///      start), Eq. 33's right-hand side has a kink (its |x' - y'|) and RK4's error there is
///      about A alpha |x''| h^2 / 8 in the force, not bounded by h lambda: the step then takes
///      m >= dt sqrt(A alpha |x''| / (8 kKinkForceTolKn)) substeps (at 80 Hz excitation and
///      2.5 A one substep across a reversal left 0.1 kN in alpha z, decaying over many samples).
///      Eqs. 35-39 come from a 1 mA table (linear interpolation) and
///      i_c at the substep times from the driver's closed form advanced by multiplication.
///      Deterministic, about a microsecond per sample.
///   4. fhat_k = Force(Eq. 34 at (ys_k, v_k), i_c(t_k)) (damper_scale).
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "io/rig_record.h"
#include "models/current_driver.h"
#include "models/mr_damper.h"
#include "models/rig_effects.h"
#include "models/servo_linear.h"
#include "scenario/scenario.h"

namespace rths::diagnosis {

/// RK4 step size bound h lambda of the force predictor (file comment, step 3).
inline constexpr double kRk4StepLambda = 0.4;
/// Where the relative velocity may reverse inside a step, RK4 substeps h with
/// A alpha |x''| h^2 / 8 <= this force [kN] (the kink of Eq. 33 at x' = y'; file comment, step 3).
inline constexpr double kKinkForceTolKn = 1e-3;

/// The nominal model: what the lab believes its rig is.
struct NominalModel {
  models::ServoModel3 actuator{};        ///< displacement path (default Eq. 30, "avg")
  bool has_damper = true;                  ///< false: the force channel is not diagnosed
  models::MrDamperParams damper{};         ///< Spencer model (default Table 3)
  bool current_dynamics = true;            ///< Eq. 40 + 75 Hz low-pass on the current
  models::CurrentDriverParams current_driver{};  ///< their form ([plant.current_driver])
  std::string source = "paper: Eq. 30 (ZOH), Spencer damper with Table 3, Eq. 40 + 75 Hz low-pass";
  std::vector<std::string> notes;          ///< what was read and how (for the report)
};

/// The paper's nominal model (the defaults above).
NominalModel PaperModel();

/// Reads --model FILE.toml: a scenario (its [plant] is the nominal model: actuator, specimen,
/// [plant.damper], current_dynamics) or a file written by `rths identify` (an actuator only).
/// A file is taken as actuator-only when it has no [run] and no [structure] table and its
/// [plant] table has neither `specimen` nor `damper`: then has_damper = false (the force channel
/// is not diagnosed) and the rest is read with the scenario parser (the file is opened and parsed
/// once: scenario::ScenarioFromToml). Throws rths::Error naming the file and key.
NominalModel LoadModel(const std::string& path);

/// Zero-phase smoothing of y and its velocity (file comment, step 1).
struct SmoothedMotion {
  std::vector<double> x_mm;     ///< smoothed displacement [mm]
  std::vector<double> v_mm_s;   ///< velocity [mm/s]
  /// Acceleration [mm/s^2], or empty. With it, the motion inside a step is the quintic Hermite
  /// through (x, v, a) at both ends, else the cubic through (x, v) (ForcePredictor).
  std::vector<double> a_mm_s2;
};
/// v = dx/dt of samples x [unit/s]: the fourth-order central difference
/// (-x_{k+2} + 8 x_{k+1} - 8 x_{k-1} + x_{k-2}) / (12 dt) inside (relative error (w dt)^4 / 30 at
/// angular frequency w), signal::Derivative's second-order one next to the ends, one-sided at the
/// ends (n >= 2).
void Differentiate(const std::vector<double>& x, double dt_s, std::vector<double>* v);

/// Throws rths::Error unless smooth_hz is in (0, 0.5/dt_s) and y has at least 4 samples.
SmoothedMotion SmoothMotion(std::span<const double> y_mm, double dt_s, double smooth_hz);

/// The damper motion from the measured y and a model prediction yhat of it (the displacement
/// channel's final model): x = yhat + S(y - yhat), S the zero-phase smoother of SmoothMotion at
/// smooth_hz; v = vhat + d/dt S(y - yhat) with vhat the model's own velocity (PredictDisplacement),
/// or, if vhat is empty, the difference quotient of x. Only the residual is smoothed, so the
/// motion keeps the model's content above smooth_hz (noise-free) and the measured content below
/// it. The model's velocity matters: a servo driven by a held command has a jump of its third
/// derivative at every sample, so a difference quotient of sampled y errs by O(dt^2 K du)
/// however smooth the data (a 40 Hz excitation at 2 kHz: a force error 15 times the noise floor).
/// With ahat_mm_s2 (the model's own acceleration, same length as vhat) the motion also carries
/// a = ahat + d^2/dt^2 S(y - yhat), and the force predictor interpolates it by a quintic inside a
/// step: a servo driven by a held command is smooth inside the step (only its jerk jumps at the
/// samples), so the quintic through (x, v, a) errs by O(dt^6) where the cubic errs by O(dt^4 x^(4)).
SmoothedMotion ModelAidedMotion(std::span<const double> y_mm, std::span<const double> yhat_mm,
                                std::span<const double> vhat_mm_s, double dt_s, double smooth_hz,
                                std::span<const double> ahat_mm_s2 = {});

/// Displacement channel prediction yhat_k for one record (file comment). `effects` may hold
/// any effects; only the displacement ones act. f_kN: the measured force f_k (load_coupling).
/// v_mm_s (optional): the prediction's velocity [mm/s] at t_k: the servo's exact velocity (its
/// state y-dot) plus the difference quotient of what the output effects add to its displacement.
/// a_mm_s2 (optional, with v_mm_s): its acceleration [mm/s^2], the servo's exact y'' plus the
/// difference quotient of the effects' velocity share.
/// y_meas_mm (optional): the measured y. With it, supply_ripple (if on) is not the library's shape
/// but the least-squares ripple at its f_hz in y_meas - (the prediction without it) over k >= first
/// (FitRipple: amplitude and phase per harmonic, per record), and its exact derivatives are added
/// to v and a.
std::vector<double> PredictDisplacement(const models::LinearServo& servo,
                                        const models::EffectSet& effects,
                                        std::span<const double> u_mm, std::span<const double> f_kN,
                                        std::vector<double>* v_mm_s = nullptr,
                                        std::vector<double>* a_mm_s2 = nullptr,
                                        std::span<const double> y_meas_mm = {}, std::size_t first = 0);

/// Force channel predictor: an immutable description (damper, current dynamics, dt).
class ForcePredictor {
 public:
  ForcePredictor(const models::MrDamperParams& damper, bool current_dynamics, double dt_s,
                 const models::CurrentDriverParams& driver = {});
  /// fhat_k for one record (file comment, steps 2-4): the smoothed motion and the current
  /// commands i_A (same length). Only current_lag and damper_scale of `effects` act (the
  /// measurement's effects, load_cell_inertia and channel_skew, are the caller's: stages::Channel).
  /// i_start_A: the command the current dynamics (and current_lag) held before the record, whose
  /// steady state they start from [A]; NaN: i_A[0] (the current set before the record started).
  std::vector<double> Predict(const SmoothedMotion& motion, std::span<const double> i_A,
                              const models::EffectSet& effects, double i_start_A = kFirstCommand) const;
  /// The same without damper_scale applied (Predict = scale x this).
  std::vector<double> PredictUnscaled(const SmoothedMotion& motion, std::span<const double> i_A,
                                      const models::EffectSet& effects, double i_start_A = kFirstCommand) const;
  /// i_start_A's default: the driver at the steady state of the record's first command.
  static constexpr double kFirstCommand = std::numeric_limits<double>::quiet_NaN();

 private:
  models::MrDamperParams damper_;
  bool current_dynamics_;
  double dt_s_;
  models::CurrentDriver driver_;
};

}  // namespace rths::diagnosis
