#pragma once
/// @file The candidate effects as parameter vectors (internal to lib/diagnosis): the lookups and
/// the checks on a fitted parameter set that the stages share. stages.h declares Candidates and
/// ToSet.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "diagnosis/stages.h"

namespace rths::diagnosis::stages {

/// The candidate named `name`; throws rths::Error for an unknown name.
const CandidateSpec& SpecOf(const std::vector<CandidateSpec>& c, const std::string& name);

/// The number of parameters a candidate's fit is free in over `records` records (the BIC's p): its
/// fitted parameters; for supply_ripple its frequency and the amplitude and phase of each of its
/// models::kRippleHarmonics harmonics per record (its reported amplitude is theirs).
int FreeParams(const CandidateSpec& spec, std::size_t records);

/// true if a fitted parameter sits on an end of its search range (within tuning::kAtBoundFraction
/// of the range, in log space for log parameters; a closed-form fit is clipped to its range): the
/// effect's model does not describe the residual there, so it is not selected (e.g. a "resonance"
/// pushed to the highest frequency, a lag at its floor).
bool AtBound(const CandidateSpec& spec, const std::vector<double>& v);

/// The library effect whose form a fitted candidate has taken, if it is another one's, else "":
/// presliding_friction whose output creeps after a reversal at less than tuning::kPlayCreepSlope of
/// its input's rate (travel / (travel + 2 loss)) is "backlash" (a play, its engagement rounded).
/// Such a fit is not an explanation of its own (like AtBound).
std::string FormOf(const CandidateSpec& spec, const std::vector<double>& v);

/// true if the set holds pure_delay beside another effect and its tau is shorter than
/// o.min_delay_samples dt: a delay below a sample is a timing convention (a ZOH lags by dt/2, a
/// discrete block and a continuous effect differ by a fraction of a sample), which a sub-sample
/// delay added to the other effect only compensates; it is not a transport delay of its own.
bool SubSampleDelayBeside(const Params& p, double dt, const Options& o);

/// An effect's parameters by their contract keys: the fitted values v (in the order of its
/// CandidateSpec) and the defaults of the parameters the diagnosis does not fit.
std::map<std::string, double> ParamMap(const std::vector<CandidateSpec>& specs, const std::string& name,
                                       const std::vector<double>& v);

}  // namespace rths::diagnosis::stages
