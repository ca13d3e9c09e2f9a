#pragma once
/// @file Compares two runs channel by channel: identical (decoded payload per (channel, k),
/// run_id aside) or where they first differ and by how much, field by field. Used by
/// `rths replay` (live outputs against the recorded ones) and `rths log compare` (CompareLogs).
#include <cstdint>
#include <string>
#include <vector>

#include "io/run_log.h"

namespace rths::io {

/// The difference of one field (a scalar, or one element of an array field, e.g. "x_mm[3]").
struct FieldDiff {
  std::string name;             ///< as in the lcmtypes, unit included (e.g. "y_mm", "f_kN")
  double rms = 0.0;             ///< RMS of b - a over the compared steps [the field's unit]
  double peak = 0.0;            ///< max |b - a| [the field's unit]
  std::int64_t peak_step = -1;  ///< where the peak is
  double rms_a = 0.0;           ///< RMS of the field in a (to judge rms and peak against)
};

/// How one channel of run b differs from run a over steps 0..steps-1.
struct ChannelDiff {
  std::string channel;
  std::int64_t steps = 0;               ///< steps compared (present in both)
  std::int64_t differing_steps = 0;     ///< steps whose payloads differ
  std::int64_t first_difference = -1;   ///< first differing step (-1: identical)
  std::vector<FieldDiff> fields;        ///< every numeric field, in message order
  bool identical() const { return first_difference < 0; }
};

/// Compares `channel` (RTHS_DESIRED, RTHS_COMMAND, RTHS_MEASURED or RTHS_CURRENT) of b against a
/// over their first `steps` steps (fewer if either log holds fewer complete steps). Throws
/// rths::Error for an unknown channel.
ChannelDiff CompareChannel(const RunLog& a, const RunLog& b, const std::string& channel, std::int64_t steps);

/// One line per channel: "RTHS_MEASURED: identical over 1000 steps" or "RTHS_MEASURED: differs
/// from step 12 (988 of 1000 steps); y_mm RMS 1.2e-3 peak 4.5e-3 at step 640 (0.8 % of its RMS);
/// ..." (fields with a non-zero difference only).
std::string Describe(const ChannelDiff& d);

/// Where one channel of two whole logs differs (CompareLogs).
struct PayloadDifference {
  enum Kind {
    kOnlyInA,    ///< the channel is in a only
    kOnlyInB,    ///< the channel is in b only
    kStepCount,  ///< both have it, with different numbers of steps
    kPayload,    ///< the same number of steps; step first_k is the first whose payloads differ
  } kind = kPayload;
  std::string channel;
  std::size_t steps_a = 0, steps_b = 0;  ///< the channel's steps in a and b
  std::int64_t first_k = -1;             ///< kPayload: the first differing step
  /// kPayload on a step channel (RTHS_DESIRED, RTHS_COMMAND, RTHS_MEASURED, RTHS_CURRENT): by how
  /// much, field by field (b - a); empty for the others.
  std::string fields;
};

/// Compares two logs payload by payload per (channel, k), run_id aside: every channel of a (by
/// name), then those only in b. Empty if the logs are identical.
std::vector<PayloadDifference> CompareLogs(const RunLog& a, const RunLog& b);

/// A difference as `rths log compare` prints it, one or more lines each ending in '\n'
/// ("RTHS_MEASURED: first difference at k = 12" and the fields' lines; "RTHS_CURRENT: only in
/// A.lcm (200 steps)"; "RTHS_DESIRED: 200 vs 150 steps"); name_a and name_b name the logs.
std::string Describe(const PayloadDifference& d, const std::string& name_a, const std::string& name_b);

}  // namespace rths::io
