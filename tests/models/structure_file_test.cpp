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

TEST_CASE("a shear-building file: story springs; all linear it is the matrix file's building exactly") {
  const fs::path dir = fs::temp_directory_path() / "rths_structure_file_test";
  fs::create_directories(dir);
  const std::string root = RTHS_SOURCE_DIR;
  // The 9-story building with linear springs: the same M, K, C as ohtori9_ns.txt (made by ShearBuilding).
  std::string text = "n 9\nfloors kg\n505000 494500 494500 494500 494500 494500 494500 494500 535000\n";
  for (const double k : {65.0, 295.6, 355.9, 191.9, 193.3, 141.9, 157.9, 80.2, 194.4})
    text += "story linear k_kN_per_mm=" + std::to_string(k) + "\n";
  text += "damping modal 0.02\n";
  std::ofstream(dir / "linear9.txt") << text;
  const auto lin = LoadStructureFile((dir / "linear9.txt").string());
  const auto mat = LoadStructureFile(root + "/data/buildings/ohtori9_ns.txt");
  CHECK((lin.M - mat.M).cwiseAbs().maxCoeff() == 0.0);
  CHECK((lin.K - mat.K).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((lin.C - mat.C).cwiseAbs().maxCoeff() < 1e-12 * mat.C.cwiseAbs().maxCoeff());
  REQUIRE(lin.springs.size() == 9);
  CHECK(mat.springs.empty());
  // The shipped yielding variant: the same initial building, Bouc-Wen stories.
  const auto bw = LoadStructureFile(root + "/data/buildings/ohtori9_ns_bouc_wen.txt");
  CHECK((bw.K - mat.K).cwiseAbs().maxCoeff() < 1e-12);
  REQUIRE(bw.springs.size() == 9);
  CHECK(bw.springs[0].kind == SpringKind::kBoucWen);
  CHECK(bw.springs[0].x_y_mm == 20.0);
  CHECK(bw.springs[7].k_kN_per_mm == 80.2);
  // Rayleigh damping: 2 % in modes 1 and 3.
  std::ofstream(dir / "rayleigh.txt") << "n 2\nfloors kg\n1000 1000\nstory bilinear k_kN_per_mm=10 b=0.05 f_y_kN=2\n"
                                         "story linear k_kN_per_mm=5\ndamping rayleigh 1 0.02 2 0.02\n";
  const auto r = LoadStructureFile((dir / "rayleigh.txt").string());
  for (double z : ModalAnalysis(r).damping_ratio) CHECK(z == doctest::Approx(0.02));
  CHECK(r.springs[0].kind == SpringKind::kBilinear);
  CHECK(r.springs[0].f_y_kN == 2.0);

  auto error_of = [&](const std::string& body) -> std::string {
    std::ofstream(dir / "bad.txt") << "n 2\nfloors kg\n1000 1000\n" << body;
    try {
      LoadStructureFile((dir / "bad.txt").string());
    } catch (const rths::Error& e) {
      return e.what();
    }
    return "";
  };
  CHECK(error_of("story linear k_kN_per_mm=1\nstory linear k_kN_per_mm=1\ndamping modal 0.02\n").empty());
  CHECK(error_of("story bouc_wen k_kN_per_mm=1 alpha=1.5\nstory linear k_kN_per_mm=1\ndamping modal 0.02\n")
            .find("bad.txt:4: story 1: alpha: must be in [0, 1)") != std::string::npos);
  CHECK(error_of("story linear k_kN_per_mm=1\nstory linear stiffness=1\ndamping modal 0.02\n")
            .find("bad.txt:5: story 2: \"stiffness=1\" is not key=value with a key of k_kN_per_mm") != std::string::npos);
  CHECK(error_of("story linear k_kN_per_mm=1\nstory elastic k_kN_per_mm=1\ndamping modal 0.02\n")
            .find("story 2: kind: \"elastic\" is not allowed") != std::string::npos);
  CHECK(error_of("story linear alpha=0.1\nstory linear k_kN_per_mm=1\ndamping modal 0.02\n")
            .find("story 1: k_kN_per_mm=... (its initial stiffness) is missing") != std::string::npos);
  CHECK(error_of("story linear k_kN_per_mm=1\ndamping modal 0.02\n").find("expected story 2") != std::string::npos);
  CHECK(error_of("story linear k_kN_per_mm=1\nstory linear k_kN_per_mm=1\ndamping viscous 0.02\n")
            .find("bad.txt:6: damping: \"viscous\"") != std::string::npos);
  CHECK(error_of("story linear k_kN_per_mm=1\nstory linear k_kN_per_mm=1\ndamping modal 1.5\n")
            .find("zeta: 1.5 is out of range [0, 1)") != std::string::npos);
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
