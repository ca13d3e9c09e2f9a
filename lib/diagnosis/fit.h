#pragma once
/// @file Effect fits (internal to lib/diagnosis): one effect's parameters on a channel, and the
/// coordinate-wise joint refit of a set (docs/diagnosis.md "Fitting").
#include <string>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "diagnosis/stages.h"

namespace rths::diagnosis::stages {

/// Fits the parameters of `name` (others in p held) on the channel; returns the SSE and updates
/// p[name]. If p already holds `name` (a refit), the search is local around its value: a bracket
/// of a factor tuning::kRefitBracketFactor (log parameters) or +- tuning::kRefitBracketFraction of
/// the range (linear ones), o.refit_grid points and golden section (2 parameters: Nelder-Mead in
/// log coordinates from the current point); else the whole range: the grid and golden section
/// (2 parameters: the 2-D grid, then Nelder-Mead). damper_scale is fitted in closed form.
double FitEffect(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, const std::string& name,
                 const Options& o);

/// Refits every effect of p, coordinate-wise (each with the others held), until a round
/// improves the SSE by less than tuning::kRefitRelTol of it (at most `rounds` rounds). Returns the SSE.
double RefitAll(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, double sse, int rounds,
                const Options& o);

}  // namespace rths::diagnosis::stages
