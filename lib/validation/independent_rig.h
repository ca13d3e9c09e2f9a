#pragma once
/// @file A second rig-record generator, written independently of the rig mode and of the effect
/// blocks (models/rig_effects.h, models/effect_rig.h, validation/synthetic.h), for validating the
/// diagnosis on records it was not built alongside (docs/diagnosis.md "Validation harness",
/// tests/diagnosis/diagnosis_independent_test.cpp). It uses only the model equations of docs/models.md
/// (sections 1, 6, 13) and docs/rig_mode.md, the parameter structs (ServoModel3 "avg",
/// MrDamperParams::Table3), and none of lib/models' simulation code. Units: mm, kN, A, s.
///
/// What differs from our generators:
///
/// * Integration: one continuous ODE for everything (servo, effects with dynamics, damper, current
///   dynamics), fixed-step classical RK4 with M substeps per record step (M >= `substeps`, raised
///   where the local stiffness lambda needs it, M >= dt lambda), the command held over each record
///   step (ZOH) and split exactly where a delayed command switches. Ours: exact ZOH matrices for
///   the servo, ARKODE (rig mode) or RK4 over a Hermite motion (blocks) for the damper.
///   The servo is realised in cascade form, G(s) = K / ((s + p)(s^2 + b s + c)):
///       w' = -p w + K u_s,   x'' = w - b x' - c x.
///   Current dynamics (Eq. 40 and the 75 Hz low-pass) as states:
///       m' = -a m + i_l,  i_40 = (a / b9) (i_l + (b9 - a) m),  i_c'' = wn^2 (i_40 - i_c) - 2 zeta wn i_c'
///   (a = pi, b9 = 9 pi, wn = 2 pi 75, zeta = 1/sqrt 2), from the steady state of i_0.
///   Damper: Eqs. 32-34, Table 3, coefficients at i_c(t) by Eqs. 35-39 evaluated directly.
/// * Effects, each in a form that differs slightly from the library's block:
///     pure_delay     u_s(t) = u(t - tau): the held command switched tau later, exactly, tau any
///                    real number (the library interpolates linearly between samples);
///     gain_error     u_s = g u (the same form: a gain is a gain);
///     oil_column     continuous q'' = w^2 (x - q) - 2 zeta w q' on the continuous servo motion
///                    (the library: ZOH of the sampled x);
///     servovalve_saturation  r' = vmax sat((x' + (x - r) / tau_r) / vmax), sat(v) = v / (1 + |v|^8)^(1/8),
///                    tau_r = 1 ms (a smooth flow limit with its own recovery; the library: a
///                    sample-wise rate limiter); or (vmax_in_loop) inside the servo loop: the
///                    piston's velocity x' = vmax sat(x_v / vmax) of the loop's velocity state x_v;
///     load_coupling  a continuous series compliance: y = x - c F(t) at every instant, F the
///                    damper force, solved as an ODE for y (F is affine in y');
///     coulomb_friction  Dahl-like lag of the lost motion: phi' = (loss (2/pi) atan(x'/v_s) - phi) / tau_f,
///                    v_s = 1.5 mm/s, tau_f = 0.3 ms, y = x - phi (the library: loss tanh(x'/0.5)
///                    of a difference quotient);
///     backlash       a play with a rounded engagement: y' = x' g(e), e = x - y, g = 0 while moving away
///                    from contact, else clamp((|e| - (h - w)) / w, 0, 1), h = gap / 2, w = 0.3 h
///                    (the library: the sharp play operator on the samples);
///     presliding_friction  Dahl's law with exponent 1.5 on the input's travel:
///                    phi' = sigma y' (1 - phi sgn(y') / loss)^1.5, sigma = rho / 2^1.5, y = x - phi, so the
///                    output's slope after a reversal is 1 - rho (the library: exponent 1 on the
///                    output's travel, solved exactly per sample);
///     command_dead_band  a smooth dead zone on the continuous loop error: the servo is driven by
///                    x + e - h tanh(e / h), e = u - x, h = width / 2, x the servo's continuous
///                    output (the library: a sharp dead zone against the sampled x_k);
///     current_lag    two first-order lags in series, tau1 = 0.8 tau, tau2 = 0.2 tau (the library:
///                    one of tau);
///     damper_scale   alpha, c0, c1 scaled by s (exactly a force scale) times a slow drift:
///                    s(t) = s (1 + drift (t / T - 1/2)), drift 1 % over the record (warming up).
///     channel_skew   the force sampled at t_k - skew from the continuous solution (the record step
///                    split at that instant; the library: a 4-point interpolant of the samples);
///     load_cell_inertia  m y'' with y'' the continuous acceleration of the specimen as the effect
///                    chain knows it (exact without displacement effects; the library: a smoothed
///                    acceleration of the model-aided motion);
///     supply_ripple  a flow ripple inside the servo loop: the piston's velocity gets
///                    sum_h a_h theta_h' cos(theta_h), theta_h = h theta + phi_h, with the pump's angle
///                    theta = 2 pi f (t + w sin(2 pi 0.1 t) / (2 pi 0.1)) (its speed wanders by w),
///                    harmonic sizes a_2/a_1, a_3/a_1 and phases drawn per case, filtered by the loop;
///                    it enters the piston's chamber, the oil column's displacement when there is one
///                    (the library: a fixed-shape sum of sines added to y);
///   Outside the library (the diagnosis must answer "unknown"):
///     ripple         y_meas += a (1 + 0.5 sin(2 pi 0.3 t)) sin(2 pi f t), an amplitude-modulated ripple;
///     cubic spring   F += k3 y^3 (a hardening bumper);
///     asymmetric valve  u_s = u (1 + a) for u > 0, u (1 - a) for u < 0.
/// * Noise: white, or anti-alias filtered (white at 8 times the record rate through a 4th-order
///   Butterworth low-pass at 0.4 / dt, then sampled), plus a slow drift of a fraction of its rms
///   (a sine of 0.02-0.1 Hz); scaled so that the sampled noise has the requested rms; optionally a
///   random-walk drift (a sensor's thermal drift) of a given multiple of the noise rms.
/// * Excitations: band noise (white through a 6th-order Butterworth low-pass and a 2nd-order
///   high-pass, both biquads written here), logarithmic chirps, random-phase multisines, and an
///   RTHS-like command: the displacement of an SDOF (f_n = lo_hz, zeta 3 %) under the El Centro
///   record (data/ground_motion/, docs/models.md section 13). Currents: pulsed on/off, constant,
///   staircase, random telegraph.
/// * Sample pairing as docs/rig_record.md says: row k holds u_k (held from t_k), y_k and f_k
///   measured at t_k, and i_k, the current command held from t_k; y_0, f_0 at rest.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/rig_record.h"

namespace rths::validation {

/// The command family of an independent record.
enum class CommandFamily { kBandNoise, kChirp, kMultisine, kEarthquake };
/// The current command's pattern.
enum class CurrentPattern { kPulsed, kConstant, kStaircase, kTelegraph };
/// The sensor noise's colour.
enum class NoiseColour { kWhite, kAntiAliased };

std::string_view Name(CommandFamily f);
std::string_view Name(CurrentPattern p);

/// The inputs of one independent record.
struct IndependentExcitation {
  double duration_s = 20.0;   ///< record length [s]
  double dt_s = 0.0005;       ///< record step [s]
  CommandFamily command = CommandFamily::kBandNoise;
  /// kBandNoise: high-pass corner (0: none); kChirp, kMultisine: lowest frequency;
  /// kEarthquake: the SDOF's natural frequency [Hz].
  double lo_hz = 0.0;
  /// kBandNoise: low-pass corner; kChirp, kMultisine: highest frequency [Hz]; kEarthquake: unused.
  double hi_hz = 20.0;
  double rms_mm = 4.0;        ///< RMS of u [mm]
  std::uint64_t seed = 1;
  CurrentPattern current = CurrentPattern::kPulsed;
  double current_max_A = 2.5;     ///< on level, top of the staircase [A]; kConstant: the current
  double current_period_s = 1.0;  ///< pulse period, staircase step, telegraph mean hold [s]
  /// > 0: the current command is on at this level [A] from the first sample until the pattern
  /// first changes (a test that starts with the damper energised); 0: the pattern from its start.
  double current_start_A = 0.0;
  /// kEarthquake: the ground acceleration [g] at 0.02 s steps (ReadGroundMotion of
  /// data/ground_motion/elcentro_1940_ns_g.txt, read by the caller); unused otherwise.
  std::vector<double> ground_g;
};

/// A ground-motion record [g]: whitespace-separated numbers (data/ground_motion/, 0.02 s steps).
/// Throws rths::Error naming the file if it cannot be read or holds fewer than 10 samples.
std::vector<double> ReadGroundMotion(const std::filesystem::path& file);

/// The truth of an independent record: effects in this generator's own forms (file comment),
/// their parameters in the library's units; 0 / negative = off unless said otherwise.
struct IndependentTruth {
  double delay_ms = 0.0;               ///< pure_delay [ms], any real value >= 0
  double gain = 1.0;                   ///< gain_error (1: off)
  double compliance_mm_per_kN = 0.0;   ///< load_coupling [mm/kN]
  double oil_f_hz = 0.0, oil_zeta = 0.1;  ///< oil_column_resonance (f 0: off)
  double friction_loss_mm = 0.0;       ///< coulomb_friction [mm]
  double backlash_gap_mm = 0.0;        ///< backlash [mm]
  double presliding_loss_mm = 0.0;     ///< presliding_friction's lost motion once sliding [mm]
  double presliding_rho = 0.8;         ///< ... and 1 - the output's slope just after a reversal, (0, 1]
  double dead_band_mm = 0.0;           ///< command_dead_band's width [mm]
  double vmax_mm_per_s = 0.0;          ///< servovalve_saturation [mm/s]
  /// servovalve_saturation's form: false, a smooth limiter on the servo's output (file comment);
  /// true, inside the loop: the piston's velocity is vmax sat(x_v / vmax) of the loop's velocity
  /// state x_v, which keeps growing while the piston is limited (the loop winds up and overshoots).
  bool vmax_in_loop = false;
  double current_lag_ms = 0.0;         ///< current_lag [ms]
  double damper_scale = 1.0;           ///< damper_scale (1: off)
  double damper_scale_drift = 0.01;    ///< relative drift of the scale over the record (only if scale != 1)
  /// channel_skew: the force channel records the load cell's force at t_k - skew [ms], taken from the
  /// continuous simulation at that instant (the step split there); any real value.
  double skew_ms = 0.0;
  /// load_cell_inertia: f += m y'' 1e-6, y'' the specimen's continuous acceleration [kg].
  double cell_mass_kg = 0.0;
  /// The current driver (Eq. 40, the low-pass, the current lags) at rest at 0 A when the record
  /// starts, whatever the first command; false: at the first command's steady state.
  bool driver_at_rest = false;
  double pump_hz = 0.0;                ///< supply_ripple's fundamental [Hz] (0: off)
  double pump_mm = 0.0;                ///< ... its fundamental's size a_1 [mm] (before the loop's filtering)
  double pump_h2 = 0.5, pump_h3 = 0.25;   ///< ... a_2 / a_1, a_3 / a_1
  double pump_phase2 = 0.0, pump_phase3 = 0.0;  ///< ... phi_2, phi_3 [rad] (phi_1 = 0)
  double pump_wander = 2e-4;           ///< ... the relative wander of the pump's speed
  // Outside the library.
  double ripple_mm = 0.0, ripple_hz = 13.0;  ///< amplitude-modulated ripple on the measured y
  double cubic_kN_per_mm3 = 0.0;       ///< F += k3 y^3
  double asymmetric_gain = 0.0;        ///< valve: u (1 +- a)
  // Noise.
  double noise_y_mm = 0.01, noise_f_kN = 0.2;  ///< sampled noise rms
  NoiseColour colour = NoiseColour::kAntiAliased;
  double drift_fraction = 0.5;         ///< slow drift amplitude / noise rms (0: none)
  /// A sensor's thermal drift on both channels: a random walk from 0 (the sensor zeroed at the
  /// start), scaled so that its rms over the record is this times the channel's noise rms (0: none).
  double walk_fraction = 0.0;
  std::uint64_t noise_seed = 11;
  /// RK4 substeps per record step, at least (raised where the local stiffness needs it).
  int substeps = 8;
};

/// The command u [mm] and current command i [A] of an excitation (n = duration / dt samples).
/// Throws rths::Error for a bad band or an earthquake command without ex.ground_g.
void MakeIndependentInputs(const IndependentExcitation& ex, std::vector<double>* u_mm, std::vector<double>* i_A);

/// Noise-free samples y_k [mm], f_k [kN] at t_k = k dt of the truth driven by u, i (file comment):
/// y_0 = 0, f_0 = the force at rest. The ripple and noise are not included. Throws rths::Error if
/// the truth combines load_coupling with coulomb_friction or backlash (not modelled; with
/// presliding_friction the compliance's ODE carries the presliding law's slope).
struct IndependentTraces {
  std::vector<double> y_mm, f_kN;
  std::size_t substeps_max = 0;   ///< largest number of RK4 substeps a record step took
};
IndependentTraces SimulateIndependent(const std::vector<double>& u_mm, const std::vector<double>& i_A, double dt_s,
                                      const IndependentTruth& truth);

/// Sensor noise of one channel: n samples of rms `rms` (colour, drift as in the truth), seeded.
std::vector<double> IndependentNoise(std::size_t n, double dt_s, double rms, NoiseColour colour, double drift_fraction,
                                     std::uint64_t seed);

/// The record: inputs, simulation, ripple and noise. source = name; metadata says which generator.
io::RigRecord MakeIndependentRecord(const IndependentExcitation& ex, const IndependentTruth& truth,
                                    const std::string& name);

}  // namespace rths::validation
