// rths-export: a run's per-step signals, with their units, as a MATLAB file (matio; v5 by
// default, v7.3/HDF5 on request) and/or a CSV table, for users without LCM (docs/export.md).
//   rths export RUN_DIR [--mat FILE.mat] [--csv FILE.csv] [--mat-version 5|7.3]
// Without --mat and --csv it writes RUN_DIR/export.mat. The signals are decoded from
// RUN_DIR/log.lcm (io::ReadRunLog: every event checked) over its complete steps; dt comes from the
// log's handshake (what ran), else from RUN_DIR/scenario.toml.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "core/error.h"
#include "io/mat_export.h"
#include "io/output_folder.h"
#include "io/run_log.h"
#include "io/run_signals.h"
#include "core/exit_code.h"
#include "scenario/scenario.h"

namespace fs = std::filesystem;

namespace {

/// The exit codes (core/exit_code.h) in the --help footer.
constexpr const char* kExitHelp =
    "Layout of the .mat file (docs/export.md): one struct 'rths' with rths.signals.<name> (n x 1 double\n"
    "per signal), rths.units.<name>, rths.descriptions.<name>, rths.names (comma-separated, column order) and\n"
    "rths.meta (run_id, dt_s, steps, planned_steps, complete, status, scenario, scenario_sha256,\n"
    "source_log, rths_version, matio_version). MATLAB/Octave: d = load('export.mat'); d.rths.signals.y_mm\n"
    "The CSV has one row per step; its header names carry the units (y_mm, f_kN, t_s; k = step index).\n"
    "\n"
    "Exit codes:\n"
    "  0  exported every step of a finished run\n"
    "  2  bad input: RUN_DIR is not a folder or has no log.lcm, the log is not an LCM event log of a run\n"
    "     (the message names the file and the byte offset), it has no complete step, an output cannot be\n"
    "     written (named; no half-written file is left), this matio cannot write v7.3; or a usage error\n"
    "  5  internal failure\n"
    "  12 the log is truncated (the run did not finish): its complete steps were exported\n"
    "(one table for every rths program: docs/lockstep.md \"Exit codes\"; 12 was 3, 5 was 1 before issue 45)";

/// The whole file, or "" if it cannot be read.
std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The step of the run: a handshake's dt_s (what ran), else the run's scenario.toml.
double StepOfRun(const rths::io::RunLog& log, const fs::path& scenario) {
  if (const double dt_s = log.StepS(); dt_s > 0.0) return dt_s;
  if (!fs::exists(scenario))
    throw rths::Error(log.source, fmt::format("no handshake says the step dt and there is no {}", scenario.string()));
  return rths::scenario::LoadScenario(scenario.string()).run.dt_s;
}

/// ", 40.8 kB" for a regular file; "" for a device or FIFO.
std::string SizeText(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) return "";
  const auto bytes = fs::file_size(p, ec);
  if (ec) return "";
  return bytes >= 10 * 1024 * 1024 ? fmt::format(", {:.1f} MB", bytes / (1024.0 * 1024.0))
                                   : fmt::format(", {:.1f} kB", bytes / 1024.0);
}

/// Exits at once after a failure: HDF5 (under matio's v7.3 writer) crashes in its exit handlers
/// when a write failed with its objects still open, which would turn exit 2 into a SIGSEGV.
[[noreturn]] int ExitNow(int code) {
  std::fflush(nullptr);
  std::_Exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rths export: a run's per-step signals with units as a MATLAB file (matio) and/or CSV"};
  rths::tools::NameCommand(app, "export");
  app.footer(kExitHelp);
  std::string run_dir, mat_path, csv_path, mat_version = "5";
  app.add_option("run_dir", run_dir, "run folder (with log.lcm, as written by rths run or rths replay)")->required();
  app.add_option("--mat", mat_path,
                 "MATLAB file to write (default: RUN_DIR/export.mat when neither --mat nor --csv is given)");
  app.add_option("--csv", csv_path, "CSV file to write: one row per step, units in the header names");
  app.add_option("--mat-version", mat_version, "MATLAB file format: 5 (MATLAB 5+, Octave, SciPy) or 7.3 (HDF5)")
      ->check(CLI::IsMember({"5", "7.3"}))
      ->capture_default_str();
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    const fs::path dir(run_dir);
    const fs::path log_path = rths::io::RunFolderLog(dir);
    if (mat_path.empty() && csv_path.empty()) mat_path = (dir / "export.mat").string();
    const fs::path scenario_path = dir / "scenario.toml";
    // Nothing the run recorded is replaced, and the two options are not swapped by mistake.
    if (!mat_path.empty()) rths::io::RefuseToReplaceRecord(mat_path, {log_path, scenario_path}, "--mat");
    if (!csv_path.empty()) rths::io::RefuseToReplaceRecord(csv_path, {log_path, scenario_path, mat_path}, "--csv");
    if (fs::path(mat_path).extension() == ".csv")
      throw rths::Error("--mat " + mat_path, "a MATLAB file named .csv: did you mean --csv? (--mat FILE.mat)");
    if (fs::path(csv_path).extension() == ".mat")
      throw rths::Error("--csv " + csv_path, "a CSV file named .mat: did you mean --mat? (--csv FILE.csv)");

    const auto log = rths::io::ReadRunLog(log_path.string());
    const std::int64_t steps = log.CompleteSteps();
    if (steps <= 0)
      throw rths::Error(log_path.string(), fmt::format("no complete step to export ({})",
                                                       log.Complete() ? "empty run" : log.TruncationReason()));
    const auto signals = rths::io::SignalsFromRunLog(log, StepOfRun(log, scenario_path));

    rths::io::ExportMeta meta;
    meta.run_id = log.run_id;
    meta.planned_steps = log.n_steps;
    meta.complete = log.Complete();
    meta.status = log.Complete() ? "finished" : log.TruncationReason();
    meta.scenario_toml = ReadText(scenario_path);
    meta.scenario_sha256 = log.ScenarioSha256();
    meta.source_log = fs::absolute(log_path).lexically_normal().string();

    std::printf("rths export: %s: %lld steps of %g s, %zu signals (run %lld, %s)\n", log_path.c_str(),
                static_cast<long long>(steps), signals.dt_s, signals.columns.size(),
                static_cast<long long>(log.run_id), log.Complete() ? "finished" : "truncated");
    if (!mat_path.empty()) {
      const auto version = mat_version == "7.3" ? rths::io::MatVersion::kV73 : rths::io::MatVersion::kV5;
      rths::io::WriteMat(mat_path, signals, meta, version);
      std::printf("  wrote %s (MATLAB v%s%s)\n", mat_path.c_str(), mat_version.c_str(), SizeText(mat_path).c_str());
    }
    if (!csv_path.empty()) {
      rths::io::WriteSignalsCsv(csv_path, signals);
      std::printf("  wrote %s (CSV%s)\n", csv_path.c_str(), SizeText(csv_path).c_str());
    }
    if (!log.Complete()) {
      std::fprintf(stderr, "rths export: note: %s: %s; exported its %lld complete steps (k = 0..%lld)\n",
                   log_path.c_str(), log.TruncationReason().c_str(), static_cast<long long>(steps),
                   static_cast<long long>(steps - 1));
      return rths::kExitTruncated;
    }
    return rths::kExitOk;
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "rths export: %s\n", e.what());
    return ExitNow(rths::kExitUsage);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths export: internal failure: %s\n", e.what());
    return ExitNow(rths::kExitInternal);
  }
}
