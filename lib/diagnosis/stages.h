#pragma once
/// @file The stages of Diagnose (diagnosis.h), over one channel's state: internal to
/// lib/diagnosis, exposed so that each stage can be tested alone (tests/diagnosis/diagnosis_stages_test.cpp).
///
/// Per channel (y, then f), in this order:
///   ScoreNominal      nominal residuals, gap, noise floor, floor ratios, whiteness;
///   SelectEffects     greedy selection on the training records (rules (a)-(c) of diagnosis.h);
///   SwapEffects       an effect replaced by another candidate that fits the training records better;
///   PruneEffects      an effect whose own share of the excess is below min_excess_reduction removed;
///   SplitLostMotion   one lost-motion effect tried as two, from splits of its lost motion;
///   WeighLostMotion   two lost-motion effects weighed against one that explains the same lost motion;
///   RetainOnTest      an effect that raises the test NRMSE by more than max_test_worsening dropped;
///   ScoreSelected     the selected effects' numbers, cumulative in selection order;
///   ApplyShrinkRule   the min_test_shrink_pct rule, the channel's status and final predictions;
///   ScoreCandidates   the numbers of the candidates not selected.
/// Diagnose gathers the records and the candidates, runs these for each channel, then ranks the
/// effects, forms the verdict and localises the residual.
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/channel_models.h"
#include "diagnosis/diagnosis.h"
#include "io/rig_record.h"
#include "models/rig_effects.h"
#include "models/servo_linear.h"

namespace rths::diagnosis::stages {

/// One fitted parameter of a candidate and its search range, resolved for the data set.
struct ParamSpec {
  std::string key;  ///< the parameter's key in models::kEffects
  double lo, hi;    ///< search range, in the parameter's unit
  bool log;         ///< searched in log space
  int grid;         ///< grid points over [lo, hi] (0: closed form)
};
/// One candidate effect: an entry of models::kEffects that the diagnosis may select, with the
/// search ranges of its fitted parameters.
struct CandidateSpec {
  const models::EffectInfo* info;
  std::string name;
  char channel;  // 'y' or 'f'
  std::vector<ParamSpec> params;
};

/// The candidates: every diagnosable entry of models::kEffects in the library's order, with the
/// search range of each fitted parameter (docs/diagnosis.md "Fitting"): an upper end given per dt
/// is search_hi_per_dt / dt_s (oil_column_resonance's f_hz: 0.4 / dt_s); one given by the data
/// (servovalve_saturation's vmax) is data_hi.
std::vector<CandidateSpec> Candidates(double dt_s, double data_hi);

/// Effect name -> parameter values, in the order of its CandidateSpec's params.
using Params = std::map<std::string, std::vector<double>>;

/// The effect set of a parameter map. Throws rths::Error for an unknown name.
models::EffectSet ToSet(const std::vector<CandidateSpec>& specs, const Params& p);

/// One record as the diagnosis uses it.
struct Data {
  std::string source;
  double dt = 0;                    ///< [s]
  std::vector<double> u, y, f, i;   ///< [mm], [mm], [kN], [A] (y, f drift-free if Options::detrend)
  SmoothedMotion motion;            ///< the damper's motion (set once y is diagnosed)
  /// The damper's smoothed acceleration [mm/s^2] (load_cell_inertia), set with the motion: the
  /// motion's own where it carries one, else the derivative of its velocity.
  std::vector<double> acc_mm_s2;
  /// The command the current dynamics held before the record [A] (EstimateCurrentStart); NaN: its
  /// first command (ForcePredictor::kFirstCommand).
  double i_start_A = ForcePredictor::kFirstCommand;
  std::size_t first = 0;            ///< first sample of every sum (warmup_s / dt, at most half the record)
  std::size_t size() const { return u.size(); }
};

/// The force channel's terms that enter linearly (Channel::Predict): damper_scale's scale and
/// load_cell_inertia's mass [kg], f = shift(scale fhat + 1e-6 mass a) (channel_skew's shift).
struct LinearForce {
  double scale = 1.0;
  double mass_kg = 0.0;
};

/// The measured force of record d that the force predictor and the measurement effects of `set`
/// predict, with the set's own scale and mass (damper_scale, load_cell_inertia), current_lag,
/// channel_skew, and the record's i_start_A. d's motion (and acc_mm_s2 for load_cell_inertia)
/// must be set.
std::vector<double> PredictForce(const Data& d, const ForcePredictor& fp, const models::EffectSet& set);

/// The record's signals and its first sample; no motion yet.
Data Prepare(const io::RigRecord& r, const Options& o);

/// A record that starts in motion (cut from a longer acquisition: max |u| over its first 10
/// samples above tuning::kMovingStartFraction of its max |u|) starts where the rig's states are not
/// at rest, but the model starts at rest: its damper's z and internal displacement need a travel of
/// a few pre-yield travels to forget the difference, its current dynamics a few time constants.
/// Then the record's first sample of the sums moves to where the command u has travelled
/// tuning::kStartTravelFactor x the model's largest pre-yield travel 1/sqrt(A (beta + gamma)) over
/// the record's current range, and, if the current command is not 0 at the start (the driver may
/// be mid-transition), tuning::kStartTimeConstants x the slowest current time constant (Eq. 40's
/// 1/a, or 1/eta) has passed; at most half the record. A note says how far.
void ExtendWarmupIfMoving(Data* d, const NominalModel& model, std::vector<std::string>* notes);

/// A record whose current command is not 0 at its first sample may start with the current dynamics
/// anywhere from rest (an amplifier switched on with the test) to the steady state of that command
/// (the current set before the test): the model's start would otherwise err for the first few time
/// constants, by up to the whole damper force at that current. The command the dynamics held before
/// the record, d->i_start_A, is fitted in [0, max i] (grid, then golden section) on the nominal
/// force residual over the samples [first, first + tuning::kStartTimeConstants x the slowest time
/// constant (Eq. 40's 1/a, or 1/eta)), the nominal force scaled by its least-squares factor over
/// those samples (a damper_scale not yet found must not pass for a start). It is taken only if it
/// leaves less than tuning::kStartCurrentGain of the window's residual at the first command (a
/// damper that hardly moves in the window cannot tell); a note says so when it differs from the first
/// command by more
/// than tuning::kStartCurrentNote of max i. Nothing to do without a damper, without current
/// dynamics or with the current off at the start. Needs d's motion (SetForceMotion).
void EstimateCurrentStart(Data* d, const ForcePredictor& fp, const NominalModel& model, std::vector<std::string>* notes);

/// --detrend (docs/diagnosis.md "Sensor drift"): a slow drift of a sensor is removed from the
/// measurement it is in, and only there, so that the model's inputs stay what drove the rig: for
/// ch = 'y' the measured y loses the slow part of its residual y - yhat(u) under `effects` (u, the
/// command, has no sensor); for 'f' the measured f loses that of f - fhat(motion) (the motion from
/// the drift-free y). The slow part: a zero-phase low-pass at tuning::kDriftHz. One note per record
/// with the drift's rms and range (notes may be null). 'f' needs fp and every record's motion set.
/// Diagnose calls it twice per channel: with the nominal model to select the effects, then, from
/// the original measurement, with the selected ones (whose own slow residual is then not taken
/// for drift), and selects again.
void RemoveSensorDrift(char ch, std::vector<Data>* recs, const models::LinearServo& servo, const ForcePredictor* fp,
                       const models::EffectSet& effects, std::vector<std::string>* notes);

/// Samples in the sums (k >= first) of every record.
std::size_t Count(const std::vector<Data>& ds);

/// Evaluates a channel's predictions for an effect set over a set of records (held by pointer:
/// the records, the servo and the force predictor must outlive it).
class Channel {
 public:
  /// ch: 'y' or 'f'; fp may be null for 'y'.
  Channel(char ch, const std::vector<Data>* recs, const models::LinearServo* servo, const ForcePredictor* fp);
  /// Predictions per record. For 'f' with damper_scale or load_cell_inertia in the set, their
  /// scale and mass are replaced by the least-squares ones over these records (closed form, jointly,
  /// clipped to their search ranges: [0.1, 10] and [0.01, 1e4] kg) and written to *fitted; with
  /// hold_linear (a held-out prediction), the set's own values are used instead.
  std::vector<std::vector<double>> Predict(const models::EffectSet& set, LinearForce* fitted = nullptr,
                                           bool hold_linear = false) const;
  /// Sum of squared residuals over the records (k >= first).
  double Sse(const std::vector<std::vector<double>>& pred) const;
  /// NRMSE [%] of a sum of squared residuals over these records.
  double NrmsePct(double sse) const;
  const std::vector<Data>& recs() const { return *recs_; }
  /// The measured channel of record r.
  std::span<const double> Meas(std::size_t r) const;

 private:
  /// 'f': the damper's force per record before the measurement's effects and the linear terms
  /// (ForcePredictor::PredictUnscaled), which depends on current_lag alone: the last few are kept
  /// (keyed by its tau, -1 without it), so that fitting a skew, a scale or a mass re-simulates
  /// nothing.
  const std::vector<std::vector<double>>& DamperForces(const models::EffectSet& set) const;

  char ch_;
  const std::vector<Data>* recs_;
  const models::LinearServo* servo_;
  const ForcePredictor* fp_;
  double meas2_ = 0;
  static constexpr std::size_t kDamperCache = 4;
  mutable std::vector<std::pair<double, std::vector<std::vector<double>>>> damper_cache_;  // oldest first
};

/// A candidate's latest trial: the channel's whole set with it, fitted on the training records.
struct Trial {
  std::string name;
  Params params;              ///< the channel's whole set with this candidate
  double sse = 0;             ///< training SSE of the set
  double excess_red = 0;      ///< rule (b): the fraction of the channel's excess it removes
  double dbic = 0;            ///< rule (a): the change of BIC
  double marginal_red = 0;    ///< rule (b): its own share of the excess without it
  bool pass = false;          ///< every rule holds
};

/// One channel's state through the stages.
struct ChannelState {
  ChannelState(char c, Channel tr, Channel te) : ch(c), train(std::move(tr)), test(std::move(te)) {}
  char ch;                           ///< 'y' or 'f'
  Channel train, test;               ///< the training and test records of the channel
  ChannelSummary summary;            ///< the channel's numbers (filled by the stages)
  /// The shortest channel_skew the channel may select [s] (selection rule 8, docs/diagnosis.md):
  /// one sample when the damper's motion carries displacement effects (y's final model has some:
  /// a shift below a sample then compensates their form's timing convention, as a sub-sample
  /// pure_delay beside another effect does), else 0. Set by Diagnose for the force channel.
  double min_skew_s = 0.0;

  // Set by ScoreNominal.
  std::size_t n_train = 0;           ///< samples in the training sums
  double var_floor = 0;              ///< sigma^2, train and test pooled [mm^2 or kN^2]
  bool structured = false;           ///< rho_c > none_ratio (train and test pooled)
  double sse_nominal = 0;            ///< training SSE of the nominal model
  double excess_nominal = 0;         ///< sse_nominal - n_train sigma^2
  std::vector<std::vector<double>> nom_test;  ///< nominal predictions, test records

  // The selection (SelectEffects .. RetainOnTest).
  Params sel;                        ///< selected effects and their parameters
  std::vector<std::string> order;    ///< selected names in the order they were added
  /// Set by ApplyShrinkRule: the selected names the test records cannot confirm (they barely act
  /// there), named in the verdict as unconfirmed; empty otherwise.
  std::vector<std::string> unconfirmed;
  double sse = 0;                    ///< training SSE with sel
  std::vector<std::vector<double>> pred_train;  ///< predictions with sel, training records
  std::map<std::string, Trial> last_trial;      ///< latest trial of every candidate not selected
  std::map<std::string, std::pair<double, double>> sel_stats;  ///< selected: (excess reduction, dBIC) when added
  /// selected: its close calls at the step it was added (EffectResult::alternatives)
  std::map<std::string, std::vector<EffectResult::Alternative>> alternatives;

  // Set by ApplyShrinkRule.
  bool retained = false;             ///< the selected effects are kept (the verdict names them)
  models::EffectSet fin_set;         ///< the final model's effects (retained ones, else none)
  std::vector<std::vector<double>> fin_test;        ///< final (retained effects), test records
  std::vector<std::vector<double>> pred_train_fin;  ///< final (retained effects), training records
};

/// true if p holds a channel_skew shorter than s.min_skew_s (rule 8): not a skew of the DAQ.
bool SkewTooShort(const ChannelState& s, const Params& p);

/// Without --detrend: true if the channel is structured (after ScoreNominal, whose nominal
/// predictions it uses) but its nominal residual less its slow part (RemoveSensorDrift's low-pass) is at the noise floor (floor ratio
/// <= none_ratio): the whole excess is a drift. Diagnose then removes it as --detrend would.
bool ExcessIsSlow(const ChannelState& s, double none_ratio);

/// Effect name -> its numbers, over both channels (names are unique across channels).
using EffectResults = std::map<std::string, EffectResult>;

/// Nominal residuals on both sets, the gap, the noise floor (train and test pooled), the floor
/// ratios and the whiteness; sets summary (diagnosed), n_train, var_floor, structured,
/// sse_nominal, excess_nominal, nom_test, and sel = {}, sse, pred_train of the nominal model.
/// Throws rths::Error naming the records if a nominal residual is not finite.
void ScoreNominal(ChannelState* s, const Options& o);

/// The channel is not diagnosed (a displacement-only test's y): its final model is the nominal one.
void MarkNotDiagnosed(ChannelState* s);

/// Greedy selection on the training records (diagnosis.h, rules (a)-(c)): while some candidate
/// passes, adds the one removing the largest fraction of the excess and refits the set jointly.
/// Sets sel, order, sse, pred_train, sel_stats, last_trial.
void SelectEffects(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o);

/// Adds `name` to the selection as SelectEffects does: `set` (the whole set with it, fitted) becomes
/// s.sel, name is appended to s.order with its rule (b) fraction and dBIC, and the training
/// prediction and SSE are made anew.
void AddEffect(ChannelState* s, const std::vector<CandidateSpec>& specs, const std::string& name, Params set,
               double excess_red, double dbic);

/// The close calls of the step that selects `best`: every other trial of the step that passed
/// every rule and whose BIC, n_eff ln(SSE_t / SSE_best) + (p_t - p_best) ln n_eff, is below
/// tuning::kCloseCallBic above best's (clipped at 0), closest first (EffectResult::alternatives).
/// p counts FreeParams over `records` training records.
std::vector<EffectResult::Alternative> CloseCalls(const std::map<std::string, Trial>& trials, const Trial& best,
                                                  double n_eff, const std::vector<CandidateSpec>& specs,
                                                  std::size_t records);
/// Up to o.swap_passes times: the effect of the set whose replacement by another candidate (fitted,
/// then the set refitted) lowers the training SSE the most, by more than tuning::kSwapMinGain of it, is
/// replaced. Each swap is a warning.
void SwapEffects(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                 std::vector<std::string>* warnings);

/// While the set holds two or more effects: the effect with the smallest own share of the excess
/// (the set refitted without it), if below o.min_excess_reduction, is removed. Each removal is a
/// warning. On return pred_train and sse are those of the final set.
void PruneEffects(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                  std::vector<std::string>* warnings);

/// The lost-motion effects (backlash, coulomb_friction, presliding_friction, command_dead_band:
/// docs/diagnosis.md "Lost motion") lose motion at reversals, and two of them together can mimic a
/// third (a play and a friction jump standing in for a short presliding travel). When the set holds
/// two or more, each single lost-motion effect is fitted in their place (from the full range, and
/// from where the set says the motion is lost: L = the sum of their lost motions, gap/2, loss,
/// width/2, as its loss, gap 2L or width 2L, with presliding travels of 0.05, 0.2 and 0.5 L), the
/// rest refitted. If the single's BIC (rule (a)'s form, its parameters against theirs) is below the
/// set's, it replaces them (a warning says so, with the set named as its close call if within
/// tuning::kCloseCallBic); if it is within tuning::kCloseCallBic above, the set stays and the single
/// is named as the first of them's close call (the verdict says "close call: or ...").
void WeighLostMotion(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings);

/// The converse of WeighLostMotion: one lost-motion effect can stand in for two (a valve's dead
/// band beside a short presliding travel fitted as one longer presliding loss), and the pair's joint
/// optimum lies in a basin the selection's trials, started from the second effect's whole range
/// beside the first's fit, do not reach. When the set holds exactly one lost-motion effect, with
/// lost motion L, each other lost-motion effect E is tried beside it from splits of L: the one's
/// lost motion scaled to (1 - phi) L, E started at phi L (gap or width 2 phi L), phi in
/// tuning::kLostMotionSplits, then both refitted with the rest. The best pair is added as the
/// selection adds an effect: if it passes the selection's rules (a)-(c) against the set (its BIC
/// lower, both effects' own shares at least min_excess_reduction, neither at a bound nor another
/// effect's form), each of the two loses at least tuning::kLostMotionMinShare of their lost motion
/// and the pair removes at least tuning::kLostMotionSplitMinGain of the excess the one left (a
/// second effect that only corrects the first's form does less). A warning says so.
void SplitLostMotion(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings);

/// In selection order, an effect whose addition raises the channel's test NRMSE by more than
/// o.max_test_worsening (relative) is dropped (a warning); if any was, the rest are refitted on the
/// training records.
void RetainOnTest(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                  std::vector<std::string>* warnings);

/// The selected effects' numbers, each with the effects selected before it (selected = true).
void ScoreSelected(const ChannelState& s, const std::vector<CandidateSpec>& specs, EffectResults* er);

/// The test NRMSE with the selected set; the min_test_shrink_pct rule on a structured test
/// residual (a warning and er's entries unselected if it fails); sets retained, the summary's
/// after_test_pct and status, fin_test and pred_train_fin.
void ApplyShrinkRule(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings, EffectResults* er);

/// The uncertainty and the constancy of the selected effects' parameters (after ApplyShrinkRule,
/// retained or unconfirmed; docs/diagnosis.md "Drift"): per fitted parameter (supply_ripple's
/// are fitted per record and left out), its standard error on the whole training set and its fit on
/// each of tuning::kDriftSegments time segments of the training records (each record's summed span
/// cut alike, segment j of every record pooled: the prediction runs over the whole record with the
/// parameter changed, the SSE is summed over the segment only; the other parameters held), with
/// their standard errors from the SSE's curvature, se^2 = 2 (SSE / n) tau_int / SSE''. A parameter
/// drifts if the segment fits' chi^2 exceeds tuning::kDriftChi2 and the last differs from the first
/// by more than tuning::kDriftMinRelative of its size and tuning::kDriftMinSigmas of that difference's
/// standard error; the effect's `drift` then says so and a warning too.
void AssessParameters(const ChannelState& s, const std::vector<CandidateSpec>& specs, EffectResults* er,
                      std::vector<std::string>* warnings);

/// The candidates not selected, from their latest trial; if a selection was not retained, every
/// candidate is refitted alone on the nominal model first (its numbers then stand on their own).
void ScoreCandidates(ChannelState* s, const std::vector<CandidateSpec>& specs, const Options& o, EffectResults* er);

}  // namespace rths::diagnosis::stages
