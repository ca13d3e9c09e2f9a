#pragma once
/// @file The verdict (internal to lib/diagnosis): the effects ranked and the verdict formed from
/// the channels' states after the stages (diagnosis.h, "Verdict").
#include <string>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "diagnosis/stages.h"

namespace rths::diagnosis {

/// res->effects: the verdict's effects in its order, the other candidates by shrink, then the
/// sensor_noise entry (the noise floor, never selected) of each diagnosed channel among the
/// first n_states.
void RankEffects(const std::vector<std::string>& verdict, stages::EffectResults* er, std::size_t n_states, Result* res);

/// res->verdict: the retained effects in order; else "unknown" if a channel is structured, "none"
/// if not. A channel left unexplained beside retained effects is a warning.
void FormVerdict(const std::vector<std::string>& verdict, const std::vector<stages::ChannelState>& st, Result* res);

}  // namespace rths::diagnosis
