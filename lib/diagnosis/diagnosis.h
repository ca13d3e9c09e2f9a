#pragma once
/// @file The sim-to-real gap diagnosis (`rths diagnose`; contract docs/rig_record.md,
/// method docs/diagnosis.md): where the nominal model is wrong, which effect of the library
/// (models/rig_effects.h) explains it, and how far the held-out gap shrinks once it is added.
///
/// Numbers, per channel c in {y, f} (f only with a damper model):
///   residual     e_k = meas_k - pred_k, over the samples k >= warmup_s / dt of every record;
///   NRMSE        100 sqrt( sum e_k^2 / sum meas_k^2 ), sums over all records of a set (Eq. 31);
///   shrink       100 (1 - NRMSE_after / NRMSE_before) on the test records;
///   noise floor  sigma_c^2 = f_Nyquist x the larger of the medians of the residual's Welch PSD over
///                [0.25, 0.5] and [0.5, 0.95] f_Nyquist (white noise of variance sigma^2 has PSD
///                sigma^2 / f_Nyq; an anti-alias filter lowers only the upper band);
///   floor ratio  rho_c = mean e_k^2 / sigma_c^2 (1 for a residual that is only white noise).
/// Selection (training records only), greedy: a candidate is fitted with the channel's selected
/// effects held, then all of the channel's effects are refitted coordinate-wise; it is added if
///   (a) BIC falls: n_eff ln(SSE_new / SSE_old) + p ln(n_eff) < 0, with n_eff = n / tau_int,
///       tau_int = 1 + 2 sum_{l>=1} r_l (the residual's autocorrelation summed up to its first
///       non-positive value): correlated samples count once per correlation time; and
///   (b) it removes at least min_excess_reduction of the channel's excess SSE over its noise
///       floor, (SSE_old - SSE_new) >= min_excess_reduction (SSE_old - n sigma^2): a tiny
///       improvement on 100k samples is not an effect; and the same fraction of the excess that
///       would remain without it, the others as refitted (its own share: a candidate that only
///       lets the others refit better is not an effect); and
///   (c) the SSE it removes is at least min_floor_gain n sigma^2: an effect weaker than the
///       noise floor is not diagnosable.
/// and while the channel's residual is above none_ratio x its floor. The candidate with the
/// largest (b) fraction goes first; after each addition the channel's effects are refitted
/// jointly (coordinate-wise until the SSE settles); the loop stops when none passes. Then swaps
/// (an effect replaced by another candidate if the refitted set has a lower training SSE) and
/// pruning (an effect whose own share of the excess falls below min_excess_reduction).
/// Held-out checks: an effect whose addition (in selection order) raises the channel's test
/// NRMSE by more than max_test_worsening (relative) is dropped and the rest refitted.
/// Verdict: "none" if rho_c <= none_ratio on every diagnosed channel (train and test pooled);
/// a channel whose test residual is structured (rho > none_ratio) keeps its selected effects
/// only if they shrink its test NRMSE by >= min_test_shrink_pct; no effect left and some channel
/// structured: "unknown"; else the selected effects in the order they were added.
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "diagnosis/channel_models.h"
#include "io/rig_record.h"
#include "models/rig_effects.h"

namespace rths::diagnosis {

/// The settings of the method a user or a lab would change (defaults: those of `rths diagnose`,
/// documented in docs/diagnosis.md). The fixed search effort and statistics are the constants of
/// diagnosis/tuning.h. Diagnose refuses options that are not IsValid() and writes the ones it used,
/// with the constants, into diagnosis.json ("options").
struct Options {
  // --- data and channels
  double warmup_s = 0.1;               ///< start of every record left out of all sums [s], >= 0
  bool detrend = false;                ///< remove the sensors' slow drift from y and f (--detrend; stages::RemoveSensorDrift)
  double smooth_hz = 20.0;             ///< zero-phase smoothing of the y residual for the force channel [Hz], > 0
  /// Upper bound of every smoothing cutoff, in cycles per sample: cutoff <= this / dt_s [Hz]; in (0, 0.5).
  double max_smooth_cycles_per_sample = 0.45;

  // --- noise floor
  /// Noise floor: the larger of the median PSDs over [noise_band_lo, noise_band_split] and
  /// [noise_band_split, noise_band_hi] (fractions of f_Nyquist), the plateau of the residual's
  /// spectrum whether the sensor noise is white or anti-alias filtered. lo in [0, 1).
  double noise_band_lo = 0.25;
  double noise_band_split = 0.5;       ///< (noise_band_lo, 1)
  double noise_band_hi = 0.95;         ///< (noise_band_split, 1]

  // --- selection rules (file comment)
  double none_ratio = 1.6;             ///< rho_c at or below this: the channel is at its noise floor, >= 1
  double min_excess_reduction = 0.25;  ///< rule (b) above (also the pruning threshold), in (0, 1)
  double min_floor_gain = 0.5;         ///< rule (c) above: the SSE removed, in units of n sigma^2, >= 0
  /// A pure_delay beside another effect of its channel must be at least this many samples long
  /// (tau >= min_delay_samples dt), else it is not added and a refit that shrinks it below is
  /// undone: a sub-sample delay next to another effect compensates that effect's form or timing
  /// mismatch (a ZOH's half sample, a continuous vs. a discrete block), it is no transport delay.
  /// Alone it may be shorter. >= 0.
  double min_delay_samples = 1.0;
  int swap_passes = 2;                 ///< rounds of swaps after the greedy loop (0: no swaps), [0, 100]

  // --- held-out checks on the test records
  double min_test_shrink_pct = 30.0;   ///< the contract's 30 % on the test records, [0, 100]
  double max_test_worsening = 0.02;    ///< an effect raising the test NRMSE by more than this (relative) is dropped, >= 0

  // --- effort of the joint refits
  int refit_grid = 5;                  ///< grid points of a local refit's bracket, [2, 1000]
  int refit_rounds = 6;                ///< coordinate rounds after an addition, a swap or a held-out drop, [1, 1000]

  // --- localisation and sensor checks
  /// A state condition holding in more than this share of the samples [%] localises nothing (a
  /// current switching every 0.1 s covers 99.9 % of them): reported as uninformative; (0, 100].
  double max_condition_samples_pct = 50.0;
  /// A channel exactly flat for this long [s] while the rig moves is a sensor fault; > 0.
  double sensor_flat_s = 0.25;

  /// Progress by stage (channel x stage), for a terminal display; empty: none. Not in ToJson.
  ProgressFn progress;

  /// True if every field is in its range; else false and a message naming the field and its
  /// allowed range in *error (if not null).
  bool IsValid(std::string* error) const;
};

/// A residual localised in frequency.
struct Band {
  std::string channel;       ///< "y" or "f"
  double lo_hz = 0, hi_hz = 0;
  double share_pct = 0;      ///< share of the channel's residual energy in the band
  double signal_share_pct = 0;  ///< share of the measured channel's energy in the band
  double rel_residual_pct = 0;  ///< 100 sqrt(residual energy / measured energy) in the band
  double coherence = -1;     ///< y only: mean coherence of u -> measured y in the band (-1: n/a)
  double gain_ratio = -1;    ///< y only: mean |H_meas / H_model| in the band (-1: n/a)
  double phase_diff_deg = 0; ///< y only: mean phase of H_meas / H_model in the band [deg]
};
/// A residual localised in a state condition.
struct Condition {
  std::string channel;
  std::string name;          ///< velocity_reversal | high_velocity | high_force | current_switching
  double share_pct = 0;      ///< share of the channel's residual energy in the condition's samples
  double samples_pct = 0;    ///< share of the samples in the condition
  /// false if the condition holds in more than Options::max_condition_samples_pct of the samples
  /// (or in none): it singles out no state, so its share says nothing about where the residual is.
  bool informative = true;
};
/// A residual localised in time.
struct TimeWindow {
  std::string channel;
  std::string record;        ///< source of the record
  double t0_s = 0, t1_s = 0;
  double share_pct = 0;      ///< share of the channel's residual energy (all test records)
};

/// One candidate effect as fitted and scored.
struct EffectResult {
  std::string name;                       ///< a library name (models::kEffects)
  std::string channel;                    ///< "y" or "f"
  std::map<std::string, double> params;   ///< the contract's keys (plus documented extras)
  double train_nrmse_after = 0;           ///< training NRMSE of the channel with it [%]
  double test_nrmse_after = 0;            ///< test NRMSE of the channel with it [%]
  double shrink_pct = 0;                  ///< test shrink against the nominal model [%]
  double excess_reduction = 0;            ///< rule (b)'s fraction when it was last tried
  double delta_bic = 0;                   ///< rule (a)'s value when it was last tried
  bool selected = false;
  /// A fitted parameter sits at an end of its search range (tuning::kAtBoundFraction): the
  /// fit did not find the effect, it ran out of range; never selected, and left out of the
  /// terminal summary (diagnosis.json keeps it).
  bool at_bound = false;
  int order = -1;                         ///< position in the verdict (selected only)
  /// Selected on the training records, but the test records do not exercise it (its fitted form
  /// barely changes their prediction), so the test can neither confirm nor refute it: why, with
  /// the training evidence (docs/diagnosis.md "Unconfirmed"). Such an effect is in the verdict
  /// (Summary prints "name (unconfirmed: why)"), not in the final model. "" otherwise.
  std::string unconfirmed;
  /// Not empty: the fit took another library effect's form, named here (presliding_friction whose
  /// output does not creep after a reversal is a play, "backlash": docs/diagnosis.md "Lost motion");
  /// never selected, and left out of the terminal summary.
  std::string form_of;
  /// Another candidate that explains a selected effect's training residual nearly as well.
  struct Alternative {
    std::string name;
    /// Its BIC minus the selected effect's, at the step the selected one was added (rule (a)'s
    /// n_eff ln(SSE_alt / SSE_sel) + (p_alt - p_sel) ln n_eff), >= 0.
    double delta_bic = 0;
    std::map<std::string, double> params;  ///< its fitted parameters (contract keys)
  };
  /// A selected effect's close calls: the candidates of its channel that passed every rule at the
  /// same step with a BIC within tuning::kCloseCallBic of it, closest first; empty if none.
  std::vector<Alternative> alternatives;
  /// A selected effect's parameters' standard errors (contract keys; stages::AssessParameters):
  /// from the curvature of the training SSE at the fit, sigma^2 = SSE / n with n counted once per
  /// correlation time of the residual. Empty for the others.
  std::map<std::string, double> params_se;
  /// A parameter of a selected effect fitted per segment of the training records (each record's
  /// summed span cut into tuning::kDriftSegments in time, segment j of every record pooled).
  struct Drift {
    std::string key;              ///< the parameter
    std::vector<double> values;   ///< its fit on each segment, in time order
    std::vector<double> se;       ///< their standard errors
    double chi2 = 0;              ///< sum ((v_j - mean_w) / se_j)^2, mean_w the se-weighted mean
  };
  /// Every fitted parameter's segment fits (selected effects; empty for the others).
  std::vector<Drift> segments;
  /// Not empty: a parameter is not constant over the training records (drifting beyond its
  /// uncertainty: tuning::kDriftChi2 and tuning::kDriftMinRelative), e.g. "drifting over the
  /// record: scale 0.97 -> 0.86": an effect that changes during the test is not that library
  /// effect, whose parameters are constants; the verdict names it with this.
  std::string drift;
};

/// Per-channel numbers.
struct ChannelSummary {
  std::string channel;
  bool diagnosed = false;
  double gap_test_pct = 0;                ///< nominal test NRMSE [%]
  double gap_train_pct = 0;               ///< nominal training NRMSE [%]
  double after_test_pct = 0;              ///< test NRMSE with the channel's selected effects [%]
  double noise_rms = 0;                   ///< sigma_c (mm or kN)
  double floor_ratio = 0;                 ///< rho_c, train and test pooled
  double floor_ratio_test = 0;            ///< rho_c on the test records
  double whiteness = 0;                   ///< Ljung-Box-like: n sum_{l=1..20} r_l^2 (test); ~20 if white
  std::string status;                     ///< "noise" | "explained" | "unconfirmed" | "test only" | "unexplained" | "not diagnosed"
};

/// A stretch where a sensor channel holds one value while the rig moves: a stuck or clipped
/// sensor, not a model error (FindFlatSensors).
struct SensorFault {
  std::string record;        ///< source of the record
  std::string channel;       ///< "y" or "f"
  double t0_s = 0, t1_s = 0; ///< the stretch [s]
  double value = 0;          ///< the value held [mm or kN]
};

/// Stretches of at least `min_s` [s] where y (or f) repeats one value exactly while the command u
/// (for f: y) does not: a real sensor always shows some noise, so an exactly flat channel under
/// motion is a stuck or clipped sensor.
std::vector<SensorFault> FindFlatSensors(const io::RigRecord& r, double min_s);

struct Result {
  std::vector<std::string> train, test;   ///< record sources
  std::string model_source;
  std::vector<ChannelSummary> channels;   ///< y, then f
  std::vector<Band> bands;
  std::vector<Condition> conditions;
  std::vector<TimeWindow> time;
  std::vector<EffectResult> effects;      ///< ranked: selected in order, then by shrink
  std::vector<std::string> verdict;
  std::vector<std::string> warnings;
  std::vector<SensorFault> sensor_faults;  ///< stuck or clipped sensor stretches (also warnings)
  double runtime_s = 0;
  double dt_s = 0;
  std::size_t samples = 0;                ///< all samples, train + test
  Options options;

  const ChannelSummary* Channel(const std::string& c) const;
};

/// Traces kept for the report's plots (test records, nominal and final models).
struct Traces {
  struct Record {
    std::string source;
    double dt_s = 0;
    std::vector<double> u, y_meas, y_nom, y_fin, f_meas, f_nom, f_fin, i, v;  // f_*: empty if no damper
  };
  std::vector<Record> test;
};

/// Runs the whole diagnosis. Records must already be valid (io::ReadRecordAny /
/// ValidateRigRecord) and share one dt (else rths::Error naming the record). `traces`, if not
/// null, receives the test records' traces for plots. Throws rths::Error.
Result Diagnose(const std::vector<io::RigRecord>& train, const std::vector<io::RigRecord>& test,
                const NominalModel& model, const Options& options, Traces* traces = nullptr);

/// The contract's JSON (docs/diagnosis.md "Output") with our extra fields; "options" holds
/// ToJson(r.options).
nlohmann::json ToJson(const Result& r);

/// Every field of the options and every constant of diagnosis/tuning.h, by its name (the
/// constants under their former option names, e.g. "golden_iters_y").
nlohmann::json ToJson(const Options& o);

/// How much Summary says.
enum class SummaryDetail {
  kBrief,  ///< the verdict and each channel's status and test NRMSE before -> after (a few lines)
  kFull,   ///< the model, records, channels, where, every effect, verdict, warnings and runtime
};

/// The verdict as text: its names, comma-separated, each unconfirmed one followed by
/// "(unconfirmed: why)" (EffectResult::unconfirmed).
std::string VerdictText(const Result& r);

/// The terminal summary.
std::string Summary(const Result& r, SummaryDetail detail = SummaryDetail::kFull);

/// The effect set for one effect name and its parameters (contract keys); throws rths::Error for
/// an unknown name or a missing key.
void SetEffect(models::EffectSet* set, const std::string& name, const std::map<std::string, double>& params);

/// NRMSE of a residual [%]: 100 sqrt(sum (m - p)^2 / sum m^2) over k >= first of each pair.
double Nrmse(std::span<const double> meas, std::span<const double> pred, std::size_t first = 0);
/// 100 (1 - after / before).
double ShrinkPct(double before_pct, double after_pct);

}  // namespace rths::diagnosis
