#pragma once
/// @file The diagnosis's fixed numbers: search effort and residual statistics that no user tunes
/// (the settings a user would change are diagnosis::Options). Each is written into diagnosis.json's
/// "options" beside the Options fields (ToJson(Options)), so a result names every number it used;
/// the static_asserts hold the ranges Options::IsValid checked when they were options.
namespace rths::diagnosis::tuning {

// --- channels
/// Displacement-only records (u = y): the damper's motion is the measured y smoothed at this
/// times Options::smooth_hz (above the excitation), at most max_smooth_cycles_per_sample / dt_s.
inline constexpr double kDisplacementOnlySmoothFactor = 4.0;
/// Upper end of servovalve_saturation's vmax search range, as a multiple of the largest measured
/// velocity of the training records (capped at the effect library's 1e9 mm/s): room above the
/// fastest motion seen, where a flow limit would start to bite.
inline constexpr double kVmaxSearchFactor = 2.0;

/// --detrend: a sensor's drift is the nominal residual's content below this [Hz] (RemoveSensorDrift):
/// slower than any excitation a test uses, and 1e-4 of a 2 kHz record's white-noise band.
inline constexpr double kDriftHz = 0.5;

// --- records that start in motion (stages::ExtendWarmupIfMoving)
/// A record starts in motion if max |u| over its first 10 samples exceeds this fraction of its max |u|.
inline constexpr double kMovingStartFraction = 0.01;
/// Its warm-up lasts until u has travelled this many times the model's largest pre-yield travel ...
inline constexpr double kStartTravelFactor = 5.0;
/// ... and this many of the current dynamics' slowest time constants have passed.
inline constexpr double kStartTimeConstants = 5.0;
/// EstimateCurrentStart: the fitted start is named in a note when it differs from the first command by
/// more than this fraction of the record's largest command.
inline constexpr double kStartCurrentNote = 0.05;
/// ... its grid over [0, max i] before golden section, and the golden-section iterations.
inline constexpr int kStartCurrentGrid = 11;
/// ... and is taken only if it leaves less than this fraction of the window's residual at the first
/// command's steady state (else the first command is kept and nothing is said).
inline constexpr double kStartCurrentGain = 0.5;
inline constexpr int kStartCurrentIters = 20;

// --- unconfirmed effects (ApplyShrinkRule)
/// Effects selected on the training records whose test shrink fails the rule are "unconfirmed"
/// rather than dropped if their fitted form changes the test prediction by less than this many
/// times the noise floor's power (sum (pred - nominal)^2 / (n sigma^2): the test does not
/// exercise them) ...
inline constexpr double kUnconfirmedTestFootprint = 1.0;
/// ... while changing the training prediction by at least this many times it.
inline constexpr double kUnconfirmedTrainFootprint = 4.0;
/// Effects found on the test records only (Diagnose's TestOnlyEffects: the training records at their
/// floor) must explain at least this share of the test's excess over the floor: nothing holds them out.
inline constexpr double kTestOnlyMinExplained = 0.9;

// --- noise floor and residual statistics
/// Welch segment length of the noise floor [samples]: 256 gives a PSD resolution of f_s / 256,
/// fine enough to find the plateau above the excitation and averaged over many segments.
inline constexpr int kNoisePsdSegment = 256;
/// Lags l = 1 .. this of the whiteness number (Ljung-Box-like; about this value if white).
inline constexpr int kWhitenessLags = 20;
/// tau_int sums the residual's autocorrelation up to this lag [samples] ...
inline constexpr int kCorrelationMaxLag = 2000;
/// ... and up to n / this of each record's n samples (the estimate is poor beyond a quarter).
inline constexpr int kCorrelationLagDivisor = 4;

// --- selection
/// The greedy loop stops after this many effects on one channel (more overfits the training set).
inline constexpr int kMaxEffectsPerChannel = 3;
/// A fitted parameter within this fraction of its search range of either end (in log space for
/// log parameters) is "at a bound": the candidate is not an explanation.
inline constexpr double kAtBoundFraction = 1e-3;
/// A swap is made if it lowers the channel's training SSE by more than this fraction.
inline constexpr double kSwapMinGain = 1e-3;

// --- lost motion (docs/diagnosis.md "Lost motion")
/// presliding_friction whose output moves at less than this fraction of its input's rate just
/// after a reversal (travel / (travel + 2 loss)) stands still there: a play (backlash) with a
/// rounded engagement, not friction's presliding creep.
inline constexpr double kPlayCreepSlope = 0.05;
/// A selected effect's alternative is a close call if its BIC exceeds the selected one's by less
/// than this (10: "very strong" evidence on the usual BIC scale).
inline constexpr double kCloseCallBic = 10.0;
/// SplitLostMotion's shares phi of one lost-motion effect's lost motion given to a second.
inline constexpr double kLostMotionSplits[] = {0.25, 0.5, 0.75};
/// SplitLostMotion: the least share of the pair's lost motion either effect must lose. A presliding
/// curve of another form than the library's is fitted better with a second lost-motion effect of a
/// fifth to a quarter of the motion beside it (independent generator, long travel); two effects of
/// a rig (a dead band beside a short presliding travel) shared it 0.4-0.6.
inline constexpr double kLostMotionMinShare = 1.0 / 3.0;
/// SplitLostMotion: the least share of the excess the one effect left that the split removes. The
/// second effect of a rig's pair took 73-98 % of it; a second effect standing in for a presliding
/// curve of another form, 27-53 % (independent generator, seeds 6-10).
inline constexpr double kLostMotionSplitMinGain = 0.6;

// --- parameter uncertainty and drift (stages::AssessParameters)
/// The training records' summed span is cut into this many segments in time, each fitted alone.
inline constexpr int kDriftSegments = 4;
/// A parameter drifts if its segment fits' chi^2 about their weighted mean exceeds this (p = 0.001
/// at kDriftSegments - 1 = 3 degrees of freedom) ...
inline constexpr double kDriftChi2 = 16.27;
/// ... and its last segment differs from its first by more than this fraction of max(|value|, 1 %
/// of its search range) (a drift a lab would care about, not a per mille the statistics can see) ...
inline constexpr double kDriftMinRelative = 0.05;
/// ... and by more than this many standard errors of that difference.
inline constexpr double kDriftMinSigmas = 4.0;
/// Segments are alike in excitation if the rms command, its rms rate / rms and the rms current differ
/// by at most this factor between any two (stages::AssessParameters); only then is a parameter of a
/// dynamic effect judged for drift (the force's linear terms always are).
inline constexpr double kSegmentExcitationRatio = 1.25;
/// A segment's fit searches the parameter within [v / this, v x this] (log parameters) ...
inline constexpr double kSegmentBracketFactor = 1.5;
/// ... or v +- this x its search range (linear ones).
inline constexpr double kSegmentBracketFraction = 0.1;
/// Golden-section iterations of a segment's fit.
inline constexpr int kSegmentGoldenIters = 12;
/// The curvature of the SSE is taken over +- this relative step (log parameters: of the value; linear
/// ones: of the search range).
inline constexpr double kCurvatureStep = 0.01;

// --- parameter search (one effect) and joint refits (coordinate-wise)
/// Golden-section iterations after the full-range grid: y effects ...
inline constexpr int kGoldenItersY = 24;
/// supply_ripple: grid points over the bracket of +- one spectral line width around the harmonic
/// spectrum's peak, before golden section (diagnosis/fit.cpp FitSupplyRipple).
inline constexpr int kRippleBracketGrid = 9;
/// ... force effects (each evaluation re-simulates the damper, so fewer).
inline constexpr int kGoldenItersF = 12;
/// Golden-section iterations of a local refit: y effects ...
inline constexpr int kRefitGoldenItersY = 14;
/// ... force effects.
inline constexpr int kRefitGoldenItersF = 8;
/// Local refit of a log parameter: the bracket [v / this, v x this].
inline constexpr double kRefitBracketFactor = 1.3;
/// Local refit of a linear parameter: the bracket v +- this x its search range.
inline constexpr double kRefitBracketFraction = 0.05;
/// A switch's second form (servovalve_saturation in the loop) is fitted within this factor of the first
/// form's fit (FitEffect).
inline constexpr double kSwitchBracketFactor = 2.0;
/// Nelder-Mead evaluations of a two-parameter fit (after its grid).
inline constexpr int kSimplexEvals = 48;
/// ... of a two-parameter local refit.
inline constexpr int kRefitSimplexEvals = 24;
/// Initial simplex step of a two-parameter fit, as a fraction of its grid spacing (log units).
inline constexpr double kSimplexStepGridFraction = 0.5;
/// Initial simplex step of a refit [log units]: first parameter ...
inline constexpr double kRefitSimplexStepFirst = 0.05;
/// ... second parameter.
inline constexpr double kRefitSimplexStepSecond = 0.1;
/// Joint refits stop when a coordinate round lowers the SSE by less than this fraction.
inline constexpr double kRefitRelTol = 1e-4;
/// Coordinate rounds refitting a candidate's trial set (a quick look; the winner gets refit_rounds).
inline constexpr int kTrialRefitRounds = 2;
/// Coordinate rounds of the set without an effect, when pruning.
inline constexpr int kPruneRefitRounds = 2;

static_assert(kDisplacementOnlySmoothFactor > 0 && kVmaxSearchFactor >= 1);
static_assert(kNoisePsdSegment >= 8 && kWhitenessLags >= 1 && kCorrelationMaxLag >= 1 && kCorrelationLagDivisor >= 1);
static_assert(kMaxEffectsPerChannel >= 1 && kAtBoundFraction >= 0 && kAtBoundFraction < 0.5);
static_assert(kSwapMinGain >= 0 && kSwapMinGain < 1);
static_assert(kPlayCreepSlope >= 0 && kPlayCreepSlope < 1 && kCloseCallBic >= 0);
static_assert(kGoldenItersY >= 0 && kGoldenItersF >= 0 && kRefitGoldenItersY >= 0 && kRefitGoldenItersF >= 0);
static_assert(kRefitBracketFactor > 1 && kRefitBracketFraction > 0 && kRefitBracketFraction <= 1);
static_assert(kSimplexEvals >= 3 && kRefitSimplexEvals >= 3);
static_assert(kSimplexStepGridFraction > 0 && kRefitSimplexStepFirst > 0 && kRefitSimplexStepSecond > 0);
static_assert(kRefitRelTol >= 0 && kRefitRelTol < 1 && kTrialRefitRounds >= 1 && kPruneRefitRounds >= 1);

}  // namespace rths::diagnosis::tuning
