// rths-structure: make and inspect structure files (docs/structures.md).
//   rths structure info FILE
//   rths structure shear --masses-kg M1,M2,... --stiffness-kN-mm K1,K2,... [--damping 0.02] --out FILE
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "models/structure_file.h"

int main(int argc, char** argv) {
  CLI::App app{"rths structure: make and inspect structure files (M, K, C as text)"};
  rths::tools::NameCommand(app, "structure");
  app.require_subcommand(1);
  std::string file, out, comment;
  std::vector<double> masses, stiffness;
  double zeta = 0.02;
  auto* info = app.add_subcommand("info", "natural frequencies, modal damping and total mass");
  info->add_option("file", file, "structure file")->required();
  auto* shear = app.add_subcommand("shear", "a lumped-mass shear building with equal modal damping");
  shear->add_option("--masses-kg", masses, "floor masses [kg], floor 1 first")->required()->delimiter(',');
  shear->add_option("--stiffness-kN-mm", stiffness, "story stiffnesses [kN/mm], story 1 first")
      ->required()
      ->delimiter(',');
  shear->add_option("--damping", zeta, "damping ratio in every mode")->capture_default_str();
  shear->add_option("--comment", comment, "comment written after the header");
  shear->add_option("--out", out, "file to write")->required();
  if (const int code = rths::tools::ParseCommandLine(app, argc, argv); code >= 0) return code;
  try {
    rths::models::StructureMatrices m;
    if (*shear) {
      m = rths::models::ShearBuilding(masses, stiffness, zeta);
      rths::models::WriteStructureFile(out, m, comment);
      file = out;
    }
    m = rths::models::LoadStructureFile(file);
    const auto modes = rths::models::ModalAnalysis(m);
    std::printf("%s: %d DOF, total mass %.6g kg\n", file.c_str(), static_cast<int>(m.M.rows()),
                m.M.sum() * 1e6);
    for (std::size_t i = 0; i < modes.frequency_hz.size(); ++i) {
      std::printf("  mode %2zu  %8.4f Hz  damping %.4f\n", i + 1, modes.frequency_hz[i], modes.damping_ratio[i]);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rths structure: %s\n", e.what());
    return rths::kExitUsage;
  }
}
