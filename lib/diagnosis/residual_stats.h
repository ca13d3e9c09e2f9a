#pragma once
/// @file Statistics of a channel's residual (internal to lib/diagnosis): its noise floor, its
/// correlation time and its whiteness (diagnosis.h, "Numbers").
#include <span>
#include <vector>

#include "diagnosis/diagnosis.h"
#include "diagnosis/stages.h"

namespace rths::diagnosis::stages {

/// sum m_k^2 over k >= first.
double SumSq(std::span<const double> m, std::size_t first);

/// Integrated autocorrelation time of the channel's residual (autocovariances of the records
/// summed): tau = 1 + 2 sum_{l>=1} r_l up to the first r_l <= 0, at most tuning::kCorrelationMaxLag
/// lags and n / tuning::kCorrelationLagDivisor of a record of n samples.
double IntegratedCorrelationTime(const Channel& ch, const std::vector<std::vector<double>>& pred);

/// Noise floor of a residual set: the level of the residual PSD's plateau above the excitation,
/// sigma^2 = f_Nyq x max(median PSD over [lo, split] f_Nyq, median PSD over [split, hi] f_Nyq)
/// (o.noise_band_lo, o.noise_band_split, o.noise_band_hi), PSDs (Welch, segments of
/// tuning::kNoisePsdSegment samples) of the records averaged with weights by their length. For
/// white noise both medians estimate the same level; a sensor's anti-alias filter lowers the upper
/// band (a 4th-order Butterworth at 0.8 f_Nyq: its median to 70 % of the plateau), never the lower one.
double NoiseFloorVar(const Channel& ch, const std::vector<std::vector<double>>& pred, const Options& o);

/// n sum_{l=1..L} r_l^2 of the residual, L = tuning::kWhitenessLags (records pooled by summing
/// autocovariances).
double Whiteness(const Channel& ch, const std::vector<std::vector<double>>& pred);

}  // namespace rths::diagnosis::stages
