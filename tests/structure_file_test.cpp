// Structure files and the 9-story benchmark building (docs/models.md section 8).
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <numeric>

#include "core/error.h"
#include "models/structure_file.h"
#include "control/current_schedule.h"

namespace fs = std::filesystem;
using namespace rths::models;

TEST_CASE("the 9-story building file: frequencies, masses, 2 % damping in every mode") {
  const auto m = LoadStructureFile(std::string(RTHS_SOURCE_DIR) + "/data/buildings/ohtori9_ns.txt");
  REQUIRE(m.M.rows() == 9);
  // Half the building's seismic mass, in kN s^2/mm (1e6 kg): 5.05e5 + 7 * 4.945e5 + 5.35e5 kg.
  CHECK(m.M.sum() == doctest::Approx((5.05e5 + 7 * 4.945e5 + 5.35e5) * 1e-6).epsilon(1e-12));
  const auto modes = ModalAnalysis(m);
  const double computed[] = {0.443, 1.181, 2.053, 3.092, 4.258};  // docs/models.md section 8 (computed)
  const double paper[] = {0.443, 1.18, 2.05, 3.09, 4.27};         // the paper's first five modes
  for (int i = 0; i < 5; ++i) {
    CAPTURE(i);
    CHECK(modes.frequency_hz[i] == doctest::Approx(computed[i]).epsilon(0.001));
    CHECK(modes.frequency_hz[i] == doctest::Approx(paper[i]).epsilon(0.005));
  }
  CHECK(modes.frequency_hz.back() < 7.5);  // no high modes: the shear model's limit (README)
  for (double z : modes.damping_ratio) CHECK(z == doctest::Approx(0.02).epsilon(1e-9));
  // A shear building: first-story stiffness 65 kN/mm couples ground and floor 1 only.
  CHECK(m.K(0, 0) == doctest::Approx(65.0 + 295.6));
  CHECK(m.K(0, 2) == 0.0);
}

TEST_CASE("structure files round-trip, and bad files are refused naming file and line") {
  const fs::path dir = fs::temp_directory_path() / "rths_structure_file_test";
  fs::create_directories(dir);
  const auto m = ShearBuilding({1000.0, 2000.0}, {10.0, 5.0}, 0.05);
  WriteStructureFile((dir / "two.txt").string(), m, "two stories");
  const auto back = LoadStructureFile((dir / "two.txt").string());
  CHECK((back.M - m.M).cwiseAbs().maxCoeff() == 0.0);
  CHECK((back.K - m.K).cwiseAbs().maxCoeff() == 0.0);
  CHECK((back.C - m.C).cwiseAbs().maxCoeff() < 1e-15);
  for (double z : ModalAnalysis(back).damping_ratio) CHECK(z == doctest::Approx(0.05));

  auto error_of = [&](const std::string& text) -> std::string {
    std::ofstream(dir / "bad.txt") << text;
    try {
      LoadStructureFile((dir / "bad.txt").string());
    } catch (const rths::Error& e) {
      return e.what();
    }
    return "";
  };
  CHECK(error_of("n 2\nM kg\n1 0\n0 x\n").find("bad.txt:4: \"x\" is not a number (in M)") != std::string::npos);
  CHECK(error_of("n 2\nM tonnes\n1 0\n0 1\n").find("matrix M must be given in kg") != std::string::npos);
  CHECK(error_of("n 2\nM kg\n1 0\n0 1\nK kN/mm\n1 2\n3 4\nC kN*s/mm\n0 0\n0 0\n").find("K is not symmetric") !=
        std::string::npos);
  CHECK(error_of("n 2\nM kg\n1 0\n0 -1\nK kN/mm\n1 0\n0 1\nC kN*s/mm\n0 0\n0 0\n").find("not positive definite") !=
        std::string::npos);
  CHECK(error_of("n 2\nM kg\n1 0\n0 1\nK kN/mm\n1 0\n0 1\nC kN*s/mm\n0 0\n0\n").find("file ends inside C") !=
        std::string::npos);
}

TEST_CASE("semiactive schedules: the 0.5 Hz, 50 % pulse of Table 2 and the constant modes") {
  rths::control::SemiactiveConfig cfg;
  cfg.mode = rths::control::SemiactiveMode::kPulse;
  const rths::control::CurrentSchedule pulse(cfg, 0.0005);
  int on = 0;
  for (int k = 0; k < 4000; ++k) on += pulse.At(k) == 2.5;
  CHECK(on == 2000);
  CHECK(pulse.At(0) == 2.5);
  CHECK(pulse.At(1999) == 2.5);
  CHECK(pulse.At(2000) == 0.0);
  CHECK(pulse.At(4000) == 2.5);  // period 2 s
  cfg.mode = rths::control::SemiactiveMode::kPassiveOn;
  CHECK(rths::control::CurrentSchedule(cfg, 0.0005).At(12345) == 2.5);
  cfg.mode = rths::control::SemiactiveMode::kConstant;
  cfg.current_A = 1.25;
  CHECK(rths::control::CurrentSchedule(cfg, 0.0005).At(7) == 1.25);
  cfg.mode = rths::control::SemiactiveMode::kPassiveOff;
  CHECK(rths::control::CurrentSchedule(cfg, 0.0005).At(7) == 0.0);
}
