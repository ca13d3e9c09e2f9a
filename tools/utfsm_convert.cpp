// rths utfsm-convert INPUT [--out FILE.csv] [--from-s S] [--to-s S]
// Converts a UTFSM measured record (data/utfsm/: the actuator DAQ export chirp_0A.txt or an MR
// damper file <amp>mm<freq>Hz<current>A.txt) into a CSV rig record (io/rig_record.h,
// io/utfsm.h for the conversions, offsets and trimming). INPUT may also be a CSV rig record or
// an LCM run log of ours, to cut it. --from-s / --to-s keep the time window
// [from, to) s of the converted record (time relative to its first sample, restarted at 0 in the
// output; io::CutRigRecord), e.g. the two halves of chirp_0A for identify-then-diagnose.
// Default output: INPUT's name with .csv, in the current folder. Exit 0 ok, 2 bad input.
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "core/error.h"
#include "io/output_folder.h"
#include "io/rig_record.h"
#include "io/utfsm.h"

int main(int argc, char** argv) {
  CLI::App app{"rths utfsm-convert: a UTFSM measured record (data/utfsm/) as a CSV rig record"};
  std::string input, out;
  double from_s = 0.0, to_s = std::numeric_limits<double>::infinity();
  app.add_option("input", input,
                 "data/utfsm/actuator/chirp_0A.txt, data/utfsm/mr_damper/*.txt, or a rig record / LCM log to cut")
      ->required();
  app.add_option("--out", out, "output CSV (default: the input's name with .csv, here)");
  app.add_option("--from-s", from_s, "keep samples from this time on [s] (relative to the first sample)")->capture_default_str();
  app.add_option("--to-s", to_s, "keep samples before this time [s] (default: to the end)");
  rths::tools::NameCommand(app, "utfsm-convert");
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    if (out.empty()) out = std::filesystem::path(input).filename().replace_extension(".csv").string();
    rths::io::RefuseToReplaceRecord(out, {input}, "--out");
    auto rec = rths::io::ReadRecordOrUtfsm(input);
    if (from_s != 0.0 || to_s != std::numeric_limits<double>::infinity())
      rec = rths::io::CutRigRecord(rec, from_s, to_s);
    rths::io::WriteRigRecord(rec, out);
    std::printf("%s: %zu samples at dt = %g s (%.3f s) -> %s\n", input.c_str(), rec.size(), rec.dt_s,
                rec.DurationS(), out.c_str());
    for (const auto& [k, v] : rec.metadata) std::printf("  %s: %s\n", k.c_str(), v.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths utfsm-convert: %s\n", e.what());
    return rths::kExitUsage;
  }
  return 0;
}
