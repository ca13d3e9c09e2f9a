// The maRTHS benchmark's loop as its reference code closes it (lib/studies/marths_loop.h).
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "ident/design_model.h"
#include "models/marths_files.h"
#include "signal/history.h"
#include "studies/marths.h"
#include "studies/marths_loop.h"

namespace mm = rths::models::marths;
using rths::studies::MarthsCompensator;
using rths::studies::MarthsLoopConfig;

namespace {

const std::string kData = std::string(RTHS_SOURCE_DIR) + "/data/marths/";

MarthsLoopConfig Base(MarthsCompensator c, bool noise) {
  MarthsLoopConfig cfg;
  cfg.K_ref = rths::models::marths::ReadMatrixCsv(kData + "reference_K_N_per_m.csv");
  cfg.M_ref = rths::models::marths::ReadMatrixCsv(kData + "reference_M_kg.csv");
  const auto rec = rths::signal::ReadHistoryFile(kData + "elcentro_m_s2.txt", 0.0);
  const std::size_t n = static_cast<std::size_t>(41.18 / cfg.dt_s + 1e-9) + 1;
  cfg.ag_m_s2 = rths::signal::ResampleHistory(rec, 0.0, 0.4, cfg.dt_s, n, 0.0);
  cfg.rig.noise_mm = noise ? mm::SensorNoiseMm(cfg.dt_s) : 0.0;
  cfg.compensators.kind = c;
  const auto p = rths::models::marths::ReadRodeacParameters(kData + "rodeac_initial_parameters.txt");
  for (int i = 0; i < 2; ++i) cfg.compensators.rodeac[i] = rths::control::MakeRodeacDesign(p.theta0[i], p.P0[i], 1.0 / cfg.dt_s);
  return cfg;
}

std::string Row(const rths::studies::MarthsLoopResult& r) {
  std::string s;
  for (const auto& [k, v] : r.j.Items()) s += fmt::format("{} {:.3f}  ", k, v);
  return s + fmt::format("V {:.3f} {:.3f}", r.max_volts[0], r.max_volts[1]);
}

}  // namespace

TEST_CASE("El Centro x 0.4, nominal plant: every compensator, noise off and on") {
  const auto models = rths::ident::MarthsDesignModels(mm::NominalPlantZpk(), 1.0 / 1024);
  for (int i = 0; i < 2; ++i) {
    MESSAGE("design model " << i + 1 << ": K " << models[i].K << " p " << models[i].p << " b " << models[i].b
                            << " c " << models[i].c << " DC " << models[i].K / (models[i].p * models[i].c));
  }
  for (bool noise : {false, true}) {
    const auto none = rths::studies::RunMarthsLoop(Base(MarthsCompensator::kNone, noise));
    MESSAGE("noise " << noise << " none:   " << Row(none));
    CHECK(none.signals.xa1_t.size() == 42169);
    for (auto kind : {MarthsCompensator::kRodeac, MarthsCompensator::kFf, MarthsCompensator::kFfLqg,
                      MarthsCompensator::kMimoFf}) {
      auto cfg = Base(kind, noise);
      for (int i = 0; i < 2; ++i) cfg.compensators.per_actuator[i].model = models[i];
      const auto r = rths::studies::RunMarthsLoop(cfg);
      MESSAGE("noise " << noise << " kind " << static_cast<int>(kind) << ": " << Row(r));
      CHECK(r.j.J2_1_pct < none.j.J2_1_pct);
      CHECK(r.j.J2_2_pct < none.j.J2_2_pct);
    }
  }
}

TEST_CASE("rths reproduce marths --quick: 15 runs, the tables, the figure, and its claims") {
  rths::studies::ReproduceOptions o;
  o.quick = true;
  o.out_dir = std::filesystem::temp_directory_path() / ("rths_test_marths_" + std::to_string(::getpid()));
  o.source_dir = RTHS_SOURCE_DIR;
  const auto s = rths::studies::ReproduceMarths(o);
  CHECK(s.rows.size() == 15);
  CHECK(s.decisions.size() == 18);
  CHECK(s.records.size() == 15);
  CHECK(std::filesystem::exists(o.out_dir / "marths_records.md"));
  CHECK(std::filesystem::exists(o.out_dir / "marths_decisions.md"));
  CHECK(std::filesystem::exists(o.out_dir / "marths_lockstep.md"));  // the shipped scenarios through the lockstep
  CHECK(std::filesystem::exists(o.out_dir / "marths_lockstep.csv"));
  CHECK(s.claims.size() == 3);
  CHECK(s.perturbed == 2);
  for (const char* f : {"marths.csv", "marths_summary.csv", "marths.md", "marths.png", "marths.dat", "marths_history.png"}) {
    CHECK(std::filesystem::exists(o.out_dir / f));
  }
  for (const auto& c : s.claims) CHECK_MESSAGE(c.holds, c.text << ": " << c.detail);
  // The perturbed runs differ from the nominal one, and the study repeats itself exactly.
  CHECK(s.rows[1].j.J2_1_pct != s.rows[0].j.J2_1_pct);
  const auto again = rths::studies::ReproduceMarths(o);
  for (std::size_t i = 0; i < s.rows.size(); ++i) CHECK(again.rows[i].j.J2_2_pct == s.rows[i].j.J2_2_pct);
  std::filesystem::remove_all(o.out_dir);
}
