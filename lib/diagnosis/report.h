#pragma once
/// @file The human-readable report of `rths diagnose`: DIR/report.html, self-contained HTML
/// (tables: summary, channels, bands, conditions, time windows, effects) with PNG plots beside it
/// made by gnuplot (io/plot.h): residual spectrum vs measured spectrum, model-vs-measured
/// FRF (u -> y) with coherence, residual against the state conditions, before/after traces.
/// Without gnuplot the HTML is written without the plots (a note says so).
#include <filesystem>

#include "diagnosis/diagnosis.h"

namespace rths::diagnosis {

/// Writes dir/report.html and its PNGs (dir must exist). Throws rths::Error if the HTML cannot
/// be written.
void WriteReport(const Result& r, const Traces& traces, const std::filesystem::path& dir);

}  // namespace rths::diagnosis
