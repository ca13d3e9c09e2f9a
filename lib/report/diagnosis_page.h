#pragma once
/// @file The human-readable page of `rths diagnose`: DIR/report.html (report/html.h: the shared
/// style, escaping, an atomic write) with tables (summary, channels, bands, conditions, time
/// windows, effects) and PNG plots beside it made by gnuplot (io/plot.h) from the diagnosis'
/// figures (diagnosis/report_figures.h): residual spectrum vs measured spectrum, model-vs-measured
/// FRF (u -> y) with coherence, residual against the state conditions, before/after traces.
/// Without gnuplot the page is written without the plots (a note says so).
#include <filesystem>

#include "diagnosis/diagnosis.h"

namespace rths::report {

/// Writes dir/report.html and its PNGs (dir must exist). Throws rths::Error if the page cannot
/// be written.
void WriteDiagnosisReport(const diagnosis::Result& r, const diagnosis::Traces& traces,
                          const std::filesystem::path& dir);

}  // namespace rths::report
