#pragma once
/// @file Least-squares fit of the Spencer MR damper model at one current to damper tests
/// (`rths identify --damper`, docs/identification.md "The MR damper"). Units: mm, kN, s, A.
///
/// Model (models/mr_damper.h, Eqs. 32-34 at one current, n = 2):
///     c1 y' = alpha z + k0 (x - y) + c0 (x' - y')                                  (Eq. 32)
///     z'    = -gamma |x' - y'| z |z| - beta (x' - y') z^2 + A (x' - y')           (Eq. 33)
///     F     = alpha z + c0 (x' - y') + k0 (x - y) + k1 (x - x0)                    (Eq. 34)
/// driven by the measured displacement x_k = y_mm of the record and a velocity v_k estimated
/// from it offline by SmoothVelocity (a zero-phase smoothing differentiator at the cut-off of
/// VelocityCutoffHz unless one is given), from rest
/// (y = x_0, z = 0) at the record's first sample.
///
/// Scale redundancy: z -> z / s with alpha -> s alpha, beta -> s beta, gamma -> s gamma,
/// A -> A / s leaves F unchanged for n = 2, so A is not identifiable apart from the others; it
/// is held at DamperFitOptions::A (default the paper's 300) and alpha, beta, gamma carry the
/// scale. The physical quantities are invariant: the yield force level alpha z_max with
/// z_max = sqrt(A / (beta + gamma)), and the pre-yield travel delta = 1 / sqrt(A (beta + gamma)).
///
/// Fit: minimise over records r and samples k
///     J = sum_r  sum_k (f_rk - F_rk)^2 / sum_k f_rk^2                         (sum of Eq. 31^2)
/// (each record weighs the same whatever its length and force level):
///   - theta = ln [alpha, c0, c1, k0, beta, gamma], bounded box (DamperFitBounds), by
///     Levenberg-Marquardt with a forward-difference Jacobian, the step projected on the box;
///   - k1 and the offset b = -k1 x0 enter F linearly and are solved by weighted linear least
///     squares at every theta (variable projection, LinearTerms); if k1 <= 0 comes out,
///     k1 = x0 = 0 and a constant force offset (the load cell's zero) is fitted instead;
///   - several starts from a rough yield-force / viscous fit of the data (f ~ F_y sgn(v) + c v)
///     with pre-yield travels delta in {0.1, 0.5, 2} mm and c1 / c0 in {1, 10}; each start runs a
///     few iterations, the best continues to convergence.
/// Integration: classical Runge-Kutta (RK4) on (y, z) with x and x' interpolated linearly
/// between samples, m substeps per sample with h = dt / m <= 0.8 / lambda, lambda =
/// 2 sqrt(A (beta + gamma)) max|v| + (A alpha + k0) / (c0 + c1) a bound on the Jacobian's
/// spectral radius (the stiffest rate: saturation of z over the pre-yield travel).
#include <span>
#include <string>
#include <vector>

#include "ident/damper_options.h"
#include "ident/fit_status.h"
#include "io/rig_record.h"
#include "models/mr_damper.h"

namespace rths::ident {

/// Velocity of a sampled displacement x [mm] at step dt_s [s] -> [mm/s]: central differences
/// (one-sided at the ends), then a 4th-order Butterworth low-pass at cutoff_hz run forward and
/// backward (zero phase; |H|^2 = 1 / (1 + (f / fc)^8) overall, -6 dB at fc) over the series
/// extended at both ends by odd reflection (no start-up transient). cutoff_hz is clipped to
/// 0.45 / dt_s. Throws rths::Error for fewer than 3 samples, dt_s <= 0 or cutoff_hz <= 0.
std::vector<double> SmoothVelocity(std::span<const double> x_mm, double dt_s, double cutoff_hz);

/// The velocity cut-off [Hz] for a record's displacement: 4 x the band edge f_e of its velocity
/// (the frequency below which 99.9 % of f^2 (S_y(f) - floor) lies, over the frequencies where
/// S_y > 10 floor; S_y a Welch PSD of y_mm, the floor the median density over the top fifth of
/// the frequencies), at least 50 Hz (the former
/// fixed default, right for slow tests) and at most 0.45 / dt_s. Why 4 x: the smoothing's
/// amplitude error is (f / f_c)^8 (SmoothVelocity), 1.5e-5 at f_e; at 1.5 x it is 4 %, and the
/// damper force, which integrates x' - y' through the stiff Bouc-Wen state, shows it (a 15 Hz
/// BLWN record: force error 0.6 % at 50 Hz, 0.04 % at 100 Hz, with the true model).
double VelocityCutoffHz(const io::RigRecord& record);

/// Substeps per sample of SimulateDamperForce for these coefficients (file comment), given the
/// largest |v| [mm/s] of the motion; at least 1, at most 4000.
int DamperSubsteps(const models::MrDamperCoefficients& k, double dt_s, double vmax_mm_s);

/// Force F_k [kN] (Eq. 34) at every sample of the motion x_k [mm], v_k [mm/s] at step dt_s,
/// from rest (y = x_0, z = 0), RK4 with `substeps` per sample (0 = DamperSubsteps). Returns NaN
/// from the first sample where the state stops being finite. Throws rths::Error if x and v
/// differ in length.
std::vector<double> SimulateDamperForce(const models::MrDamperCoefficients& k, std::span<const double> x_mm,
                                        std::span<const double> v_mm_s, double dt_s, int substeps = 0);

/// The record's source, or "record" if it has none (where an error names it).
std::string RecordName(const io::RigRecord& record);

/// Throws rths::Error naming the record if it has fewer than 3 samples or its y_mm, f_kN columns
/// differ in length from its time axis.
void CheckDamperColumns(const io::RigRecord& record);

/// A record's weight in the fits' cost J, 1 / sum_k f_k^2 [1/kN^2]; throws rths::Error naming the
/// record if its force is zero throughout.
double ForceWeight(const io::RigRecord& record);

/// The largest |f| [kN] over the records.
double PeakForce(const std::vector<io::RigRecord>& records);

/// The force terms that enter linearly, F = F_nl + k1 x + b (Eq. 34's k1 (x - x0) with
/// b = -k1 x0, plus a load cell's zero): weighted least squares over e = f - F_nl, by sums.
/// k1 must be > 0 (an accumulator); if the fit gives k1 <= 0, k1 = x0 = 0 and the offset is the
/// weighted mean of e alone: the load cell's zero, which k1 (x - x0) cannot carry then
/// (docs/identification.md "Force offset").
struct LinearTerms {
  double sxx = 0, sx = 0, s1 = 0, sxe = 0, se = 0;  ///< the weighted sums

  /// Adds sample x [mm] with residual e = f - F_nl [kN] at weight w.
  void Add(double w, double x, double e) {
    sxx += w * x * x;
    sx += w * x;
    s1 += w;
    sxe += w * x * e;
    se += w * e;
  }
  struct Solution {
    double k1 = 0.0;         ///< [kN/mm], >= 0
    double x0 = 0.0;         ///< [mm]; 0 if k1 = 0
    double offset_kN = 0.0;  ///< the constant force when k1 = 0 [kN]; 0 if k1 > 0
    /// k1 x + b at displacement x [mm]: the linear part of F [kN].
    double At(double x_mm) const { return k1 * (x_mm - x0) + offset_kN; }
  };
  Solution Solve() const;
};

/// One record's score: Eq. 31 on force, sqrt(sum (f - F)^2 / sum f^2) x 100 %.
struct DamperRecordScore {
  std::string source;     ///< the record's path
  std::size_t samples = 0;
  double dt_s = 0.0;
  double velocity_cutoff_hz = 0.0;  ///< of the velocity the prediction was driven with [Hz]
  double peak_force_kN = 0.0;   ///< max |f|
  double nrmse_f_pct = 0.0;     ///< of the fitted (or given) model; inf if F is not finite
};

/// The score of a force prediction F_kN [kN] of `record` (one value per sample), made with a
/// velocity smoothed at velocity_cutoff_hz [Hz].
DamperRecordScore ScoreForce(const io::RigRecord& record, std::span<const double> F_kN, double velocity_cutoff_hz);

/// The fitted model at one current and how well it fits.
struct DamperFitResult {
  double current_A = 0.0;                  ///< the current of the records [A]
  models::MrDamperCoefficients coef{};     ///< alpha, c0, c1, beta, gamma, A, n = 2, k0, k1, x0
  std::vector<DamperRecordScore> records;  ///< per training record
  double cost = 0.0;                       ///< J at the optimum (file comment)
  int best_start = 0;                      ///< index of the start that won
  int iterations = 0;                      ///< LM iterations of the winning start, all phases
  bool converged = false;                  ///< relative cost change or step below tolerance
  std::vector<double> start_costs;         ///< J of every start after its first iterations
  FitStatus status;                        ///< how the fit ended (ident/fit_status.h)
  /// The load cell's zero on the training records [kN] when k1 = 0 (LinearTerms); not part of
  /// the damper model (a run does not add it), added to the model's force when it is scored.
  double force_offset_kN = 0.0;
  /// Multi-line text: the coefficients, the derived yield force and pre-yield travel, the errors.
  std::string Report() const;
};

/// Fits the model at options.current_A to the records (their y_mm as x, f_kN as F; see the file
/// comment; the options of the other fit are not read), the parameters options.hold names held
/// (throws rths::Error, where "--hold", for a name the fit lacks or a value outside its range); the
/// status flags implausible values (plausible_range.h). Throws rths::Error (where = the record's
/// source) if a record's current differs from current_A by more than the tolerance or its force
/// is all zero; (where = "DamperFitOptions") for invalid options or no current_A; if no start
/// gives a finite cost.
DamperFitResult FitDamper(const std::vector<io::RigRecord>& records, const DamperFitOptions& options);

/// Force prediction F_k [kN] of `coef` plus force_offset_kN on a record's motion, with the velocity
/// of SmoothVelocity(y_mm, dt_s, velocity_cutoff_hz); 0 = VelocityCutoffHz(record).
std::vector<double> PredictDamperForce(const models::MrDamperCoefficients& coef, const io::RigRecord& record,
                                       double velocity_cutoff_hz = 0.0, double force_offset_kN = 0.0);

/// Eq. 31 on force of PredictDamperForce on a record (held-out check).
DamperRecordScore ScoreDamper(const models::MrDamperCoefficients& coef, const io::RigRecord& record,
                              double velocity_cutoff_hz = 0.0, double force_offset_kN = 0.0);

/// The model file's lines for a fitted force offset (LinearTerms): a comment, and the key
/// `force_offset_kN` of the [fit] table (which must come last); "" if offset_kN is 0.
std::string ForceOffsetComment(double offset_kN);
std::string ForceOffsetKey(double offset_kN);

/// v as a TOML float (10 significant digits, always with a '.' or an exponent).
std::string TomlFloat(double v);

/// A [plant.damper] table with every MrDamperParams field (models::kMrDamperFields), one per line
/// (a TOML float each).
std::string DamperTable(const models::MrDamperParams& params);

/// The coefficients as current-independent MrDamperParams: p_a = p_b = the value, p_c = 0
/// (Eqs. 35-39 then give the value at every current).
models::MrDamperParams ParamsAtOneCurrent(const models::MrDamperCoefficients& k);

/// The model as a TOML fragment a scenario (and `rths diagnose --model`) reads:
///     [plant.damper]
///     alpha_a = ..  alpha_b = ..  alpha_c = 0  ...  A = ..  n = 2  k0 = ..  k1 = ..  x0 = ..
/// every MrDamperParams field (one per line), with '#' comments: `title`, the current, each
/// record's error, the fit's status (FitStatus::Comment); then the [fit] table. No [plant] table,
/// so it can follow an actuator fragment of `rths identify` (which has [plant] and [controller])
/// in one file.
std::string DamperTomlFragment(const DamperFitResult& fit, const std::string& title);

}  // namespace rths::ident
