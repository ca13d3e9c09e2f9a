#pragma once
/// @file Least-squares fit of the current-dependent Spencer MR damper model (Eqs. 32-39) to
/// damper tests with any control history: a current or a voltage, constant, pulsed, switched
/// (`rths identify --damper` without `--current`; docs/identification.md "The MR damper, any
/// input"). Units: mm, kN, s; the control input in A (current) or V (voltage).
///
/// Model. The command v_k of the record (held over [t_k, t_{k+1})) passes through the control
/// filter, then sets the parameters, then drives Eqs. 32-34 with the measured motion:
///
///     u' = -eta (u - v)                     first-order filter of Spencer et al. (1997), or
///                                           the paper's Eq. 40 + 75 Hz low-pass (fixed), or none
///     p(u) = p_b + (p_a - p_b) exp(-p_c u)  for p in {alpha, c0, c1, beta, gamma}  (Eqs. 35-39)
///     c1 y' = alpha z + k0 (x - y) + c0 (x' - y')                                  (Eq. 32)
///     z'    = -gamma |x' - y'| z |z| - beta (x' - y') z^2 + A (x' - y')           (Eq. 33)
///     F     = alpha z + c0 (x' - y') + k0 (x - y) + k1 (x - x0)                    (Eq. 34)
///
/// with x_k = y_mm and x'_k from SmoothVelocity (damper_fit.h) at a cut-off chosen from the
/// record's band (VelocityCutoffHz), from rest (y = x_0, z = 0, u = v_0).
///
/// Fit: minimise J = sum_r sum_k (f_rk - F_rk)^2 / sum_k f_rk^2 (each record weighs the same)
/// over theta = ln [alpha_a, alpha_b, alpha_c, c0_a, c0_b, c0_c, c1_a, c1_b, c1_c, beta_a,
/// beta_b, beta_c, gamma_a, gamma_b, gamma_c, k0, eta] (eta only for the first-order filter),
/// in a box, by Levenberg-Marquardt with a forward-difference Jacobian (its columns computed in
/// parallel; the result does not depend on the number of threads); k1 and b = -k1 x0 enter
/// linearly and are solved at every theta (variable projection, LinearTerms of damper_fit.h: a
/// constant force offset instead when k1 comes out <= 0), or held at 0 without the accumulator. A is held (scale redundancy, damper_fit.h). Starts: rough yield-force /
/// viscous fits of the samples at the lowest and at the highest filtered input give p_a and
/// p_b; pre-yield travels (at the low, high end) in {(0.1, 0.1), (0.1, 0.5), (0.5, 0.5),
/// (0.5, 2), (2, 2)} mm x c1/c0 in {1, 10}; every start runs a few iterations on the first
/// quarter of each record (at least 3 s), the best continues on all the data to convergence.
///
/// Integration: per sample, the coefficients at the sample times t_k (5 exponentials each),
/// linear in between; RK4 on (y, z) with x, x' and the coefficients interpolated linearly,
/// m_k substeps over step k -> k+1 with h lambda_k <= 0.8, lambda_k the rate bound of
/// damper_fit.h with the coefficients and |x'| of the step's two ends (at most
/// kMaxSpencerSubsteps: beyond that a trial is refused as too stiff; a prediction gives NaN).
/// The Jacobian's columns keep the base point's m_k.
#include <span>
#include <string>
#include <vector>

#include "ident/damper_fit.h"
#include "ident/damper_options.h"
#include "ident/fit_status.h"
#include "io/rig_record.h"
#include "models/current_driver.h"
#include "models/mr_damper.h"

namespace rths::ident {

/// Most substeps per sample the fit integrates with (file comment).
inline constexpr int kMaxSpencerSubsteps = 64;

/// The fitted model and how well it fits.
struct SpencerFitResult {
  models::MrDamperParams params{};          ///< Eqs. 32-39 (rates per A or per V)
  models::CurrentDriverParams driver{};     ///< the filter (kFirstOrder: the fitted eta)
  ControlFilter filter = ControlFilter::kFirstOrder;
  bool voltage = false;                     ///< the input is a voltage [V] (else a current [A])
  double input_min = 0.0, input_max = 0.0;  ///< range of the commands fitted [A or V]
  /// The distinct input levels [A or V], ascending, if every record holds its command constant
  /// (the design that decides what is held: fit_status.h); empty if a command varies.
  std::vector<double> levels;
  std::vector<DamperRecordScore> records;   ///< per training record
  double cost = 0.0;
  int best_start = 0;
  int iterations = 0;
  bool converged = false;
  std::vector<double> start_costs;
  double seconds = 0.0;                     ///< wall time of the fit [s]
  FitStatus status;                         ///< how the fit ended (ident/fit_status.h)
  std::vector<std::string> warnings;        ///< about the records (negative commands taken as 0)
  /// The load cell's zero on the training records [kN] when k1 = 0 (LinearTerms, damper_fit.h):
  /// not part of the damper model, added to its force when it is scored.
  double force_offset_kN = 0.0;
  /// Multi-line text: the parameters at the ends of the input range, eta, the errors.
  std::string Report() const;
};

/// The command the model is driven with: the record's v_V if voltage (throws if it has none),
/// else its i_A (throws if it has none).
std::span<const double> ControlInput(const io::RigRecord& record, bool voltage);

/// Largest share of a record's samples whose negative command is taken as noise (CommandForModel).
inline constexpr double kMaxNegativeShare = 0.01;

/// The command a damper model is driven with, and what was done to it.
struct ModelCommand {
  std::vector<double> v;       ///< the command [A or V], every sample >= 0
  std::size_t negatives = 0;   ///< samples that were negative (set to 0)
  double worst = 0.0;          ///< the most negative one [A or V]
  std::string warning;         ///< "" if none was negative
};

/// ControlInput with its negative samples set to 0 (docs/identification.md "Negative commands"):
/// a real DAQ's command around 0 V has noise and the anti-alias filter's ringing at steps. Allowed
/// if at most kMaxNegativeShare of the samples are negative and none is below minus the largest
/// command; else throws rths::Error naming the record, the count, the worst value and the rule
/// (a bipolar command: Eqs. 35-39 take an input >= 0).
ModelCommand CommandForModel(const io::RigRecord& record, bool voltage);

/// true if the fit drives the model with the records' v_V (DamperInput::kVoltage, or kAuto and the
/// first record has no i_A), false for i_A.
bool UsesVoltage(const std::vector<io::RigRecord>& records, DamperInput input);

/// Fits the model to the records (file comment), driven by the input UsesVoltage(records,
/// options.input) picks, through CommandForModel (options.current_A and current_tolerance_A are
/// not read); what the records cannot determine is held (fit_status.h), and what options.hold
/// names (over that), and the result's status says how the fit ended and which values are
/// implausible (plausible_range.h). Throws rths::Error (where = the record's source) for a record without
/// that column, too short, with zero force or a command CommandForModel refuses; (where = "DamperFitOptions") for bad options; if no start gives a finite cost.
SpencerFitResult FitSpencer(const std::vector<io::RigRecord>& records, const DamperFitOptions& options = {});

/// Force prediction F_k [kN] of the model on a record's motion and command (NaN from the first
/// non-finite sample). velocity_cutoff_hz 0 = VelocityCutoffHz(record).
std::vector<double> PredictSpencerForce(const models::MrDamperParams& params, const models::CurrentDriverParams& driver,
                                        ControlFilter filter, const io::RigRecord& record, bool voltage,
                                        double velocity_cutoff_hz = 0.0, double force_offset_kN = 0.0);

/// Eq. 31 on force of the model on a record (held-out check).
DamperRecordScore ScoreSpencer(const models::MrDamperParams& params, const models::CurrentDriverParams& driver,
                               ControlFilter filter, const io::RigRecord& record, bool voltage,
                               double velocity_cutoff_hz = 0.0, double force_offset_kN = 0.0);

/// The model as a model file `rths run`, `design` and `diagnose --model` read: '#' comments
/// (title, input unit, errors), then [plant] current_dynamics, [plant.damper] (every
/// MrDamperParams field) and [plant.current_driver] (the filter).
std::string SpencerModelToml(const SpencerFitResult& fit, const std::string& title);

}  // namespace rths::ident
