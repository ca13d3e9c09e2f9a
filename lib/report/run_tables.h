#pragma once
/// @file The tables and the banner of the run report (internal to report/run_report.cpp), as HTML
/// rows from a run folder's decoded contents (RunData): the scenario's settings, the results
/// (summary.json's, else the log's), the real-time figures, and the warnings.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "report/run_report.h"

namespace rths::report::run_tables {

/// A number of summary.json, or nullopt.
std::optional<double> JsonNumber(const nlohmann::json& j, const char* key);
/// A string of summary.json, or `fallback`.
std::string JsonText(const nlohmann::json& j, const char* key, const std::string& fallback = "");

/// Rows: the scenario file, name, step, controller, plant, structure, excitation, current, pacing.
std::string ScenarioTable(const RunData& d);
/// Rows: status, steps, Eq. 31, peaks, extrapolation errors, rate, link, failure, participants.
std::string MetricsTable(const RunData& d);
/// The "Real time" section (heading and table) of a paced run; "" if summary.json has none.
std::string RealtimeTable(const nlohmann::json& j);
/// The banner lines: why the page is not the report of a clean, finished run; `failed` is set if
/// the run did not finish (the first line is then the headline).
std::vector<std::string> Warnings(const RunData& d, bool* failed);

}  // namespace rths::report::run_tables
