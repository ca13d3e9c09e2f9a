// rths-utfsm-convert INPUT [--out FILE.csv]
// Converts a UTFSM measured record (data/utfsm/: the actuator DAQ export chirp_0A.txt or an MR
// damper file <amp>mm<freq>Hz<current>A.txt) into a CSV rig record (io/rig_record.h,
// io/utfsm.h for the conversions, offsets and trimming). Default output: INPUT's name with
// .csv, in the current folder. Exit 0 ok, 2 bad input.
#include <cstdio>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "io/rig_record.h"
#include "io/utfsm.h"

int main(int argc, char** argv) {
  CLI::App app{"rths-utfsm-convert: a UTFSM measured record (data/utfsm/) as a CSV rig record"};
  std::string input, out;
  app.add_option("input", input, "data/utfsm/actuator/chirp_0A.txt or data/utfsm/mr_damper/*.txt")->required();
  app.add_option("--out", out, "output CSV (default: the input's name with .csv, here)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    const auto rec = rths::io::ReadUtfsm(input);
    if (out.empty()) out = std::filesystem::path(input).filename().replace_extension(".csv").string();
    rths::io::WriteRigRecord(rec, out);
    std::printf("%s: %zu samples at dt = %g s (%.3f s) -> %s\n", input.c_str(), rec.size(), rec.dt_s,
                rec.DurationS(), out.c_str());
    for (const auto& [k, v] : rec.metadata) std::printf("  %s: %s\n", k.c_str(), v.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths-utfsm-convert: %s\n", e.what());
    return 2;
  }
  return 0;
}
