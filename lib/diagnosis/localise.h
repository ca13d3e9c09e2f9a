#pragma once
/// @file "Where" of the diagnosis (docs/diagnosis.md "Localisation"): the nominal residual of
/// the test records split by frequency band, state condition and time window.
///
/// Bands: fixed edges 0, 1, 2, 5, 10, 20, 50, 100, 200, 500 Hz and Nyquist; per band the
/// residual's Welch energy (Hann, 50 %, segments of min(2 s, n/8)) as a share of the channel's
/// residual energy, beside the measured channel's share; for y, the model-vs-measured FRF ratio
/// H1(u -> y_meas) / H1(u -> y_model) and the coherence of u -> y_meas, averaged over the band.
/// Conditions (masks on samples, shares of residual energy vs shares of samples):
///   velocity_reversal  within +-10 ms of a sign change of the smoothed velocity;
///   high_velocity      |v| > 1.5 rms(v);
///   high_force         |f_meas| > 1.5 rms(f_meas) (skipped if the record has no force);
///   current_switching  within 100 ms after a change of the current command by more than 0.05 A.
/// Time: windows of 1 s (records shorter than 10 s: a tenth of the record), the 5 largest
/// shares of the channel's residual energy over all test records.
#include <span>
#include <string>
#include <vector>

#include "diagnosis/diagnosis.h"

namespace rths::diagnosis {

/// One test record's signals for localisation (k >= first only are used).
struct LocaliseInput {
  std::string source;
  double dt_s = 0;
  std::size_t first = 0;
  std::span<const double> u, meas, pred, v, f_meas, i;
};

/// Localises the residual meas - pred of channel `channel` ("y" or "f") over the records.
void Localise(const std::string& channel, const std::vector<LocaliseInput>& recs, std::vector<Band>* bands,
              std::vector<Condition>* conditions, std::vector<TimeWindow>* time);

/// Condition masks of one record (same length as v): 1 where the condition holds.
struct ConditionMasks {
  std::vector<std::string> names;
  std::vector<std::vector<char>> masks;
};
ConditionMasks MakeConditionMasks(const LocaliseInput& r);

}  // namespace rths::diagnosis
