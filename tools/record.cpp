// rths record RUN_DIR [--out FILE.csv]
// Writes a run's plant-side signals as a CSV rig record (docs/rig_record.md "Rig record,
// CSV"; io/rig_record.h): t_s, u_mm (command_t), y_mm and f_kN (measured_t, as the plant published
// them: with its sensor noise), i_A (current_t, the commanded current), r_mm (desired_t), over the
// run's complete steps. So a run of ours (e.g. the rig mode: docs/rig_mode.md) can go to
// `rths diagnose` or to another lab. Default output: RUN_DIR/record.csv.
// Exit 0 ok, 2 bad input (no such run folder, no log.lcm, a log that is not a usable record).
#include <cstdio>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "io/output_folder.h"
#include "io/rig_record.h"
#include "io/run_log.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"rths record: a run's plant-side signals (u, y, f, i, r) as a CSV rig record"};
  std::string run_dir, out;
  app.add_option("run_dir", run_dir, "run folder written by `rths run` (holds log.lcm)")->required();
  app.add_option("--out", out, "output CSV (default: RUN_DIR/record.csv)");
  rths::tools::NameCommand(app, "record");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  fs::path log_path;
  try {
    log_path = rths::io::RunFolderLog(run_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths record: %s\n", e.what());
    return rths::kExitUsage;
  }
  try {
    if (out.empty()) out = (fs::path(run_dir) / "record.csv").string();
    rths::io::RefuseToReplaceRecord(out, {log_path}, "--out");
    const rths::io::RunLog log = rths::io::ReadRunLog(log_path.string());
    rths::io::RigRecord rec = rths::io::RigRecordFromRunLog(log, log_path.string());
    rec.metadata.emplace_back("producer", "rths record");
    std::string reason = log.AbortReason();
    for (char& c : reason) {
      if (c == '\n' || c == '\r') c = ' ';  // one metadata line
    }
    if (!reason.empty()) rec.metadata.emplace_back("run_stopped", reason);
    rths::io::WriteRigRecord(rec, out);
    std::printf("%s: %zu samples at dt = %g s (%.3f s) -> %s\n", run_dir.c_str(), rec.size(), rec.dt_s,
                rec.DurationS(), out.c_str());
    if (!reason.empty()) {
      std::printf("  note: the run stopped early (%s); the record holds its complete steps\n", reason.c_str());
    }
    for (const auto& w : rec.warnings) std::fprintf(stderr, "rths record: warning: %s\n", w.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths record: %s\n", e.what());
    return rths::kExitUsage;
  }
  return 0;
}
