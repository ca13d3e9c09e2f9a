#pragma once
/// @file How much a run will write, and whether the disk has room for it.
#include <filesystem>
#include <string>

#include "scenario/scenario.h"

namespace rths::supervisor {

/// Bytes reserved for summary.json before the run (written in place at the end).
inline constexpr std::size_t kSummaryReserve = 64 * 1024;
/// Runs that will write more than this [bytes] get a warning first.
inline constexpr double kWarnBytes = 2e9;

/// Output the run will write [bytes]: log.lcm (exact), signals.csv (a bound), and in the total
/// the reserved summary and some slack for the copied scenario and the participants' own logs.
struct OutputEstimate {
  double log_bytes = 0.0, csv_bytes = 0.0, total_bytes = 0.0;
};
OutputEstimate EstimateOutput(const scenario::Scenario& s);

/// Free bytes for an unprivileged writer on the file system that will hold `dir` (-1 if unknown).
double FreeBytes(std::filesystem::path dir);

/// Throws rths::Error naming `out` if a run of `s` writing `estimate` does not fit in its free
/// space.
void CheckDiskSpace(const std::filesystem::path& out, const scenario::Scenario& s, const OutputEstimate& estimate);

/// "12.3 MB".
std::string Megabytes(double bytes);

}  // namespace rths::supervisor
