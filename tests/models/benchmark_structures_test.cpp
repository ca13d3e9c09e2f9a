// models/benchmark_structures + the structure file's iota line: the RTHS benchmark's 3-story
// reference structure and its case-1 partition (Silva et al. 2020), and the data files made from
// them. RTHS_WRITE_DATA=1 rewrites data/buildings/silva3_*.txt from Silva3Structures().
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <Eigen/LU>
#include <fmt/format.h>

#include "core/error.h"
#include "models/benchmark_structures.h"
#include "models/structure.h"
#include "models/structure_file.h"

namespace fs = std::filesystem;
using namespace rths::models;

namespace {

const std::string kData = std::string(RTHS_SOURCE_DIR) + "/data/buildings/";

/// max |a - b| / max |b|, relative to the largest entry.
double RelDiff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

fs::path TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("rths_bstruct_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST_CASE("Silva3Structures: the benchmark's numbers in project units") {
  const BenchmarkStructures b = Silva3Structures();
  // M = 1000 I3 kg = 1e-3 kN s^2/mm; K = 1e7 N/m x [...] = 10 kN/mm x [...].
  CHECK(b.reference.M.isApprox(Eigen::MatrixXd::Identity(3, 3) * 1e-3, 1e-15));
  CHECK(b.reference.K(0, 0) == doctest::Approx(26.055).epsilon(1e-14));
  CHECK(b.reference.K(0, 1) == doctest::Approx(-23.134).epsilon(1e-14));
  CHECK(b.reference.K(0, 2) == doctest::Approx(5.937).epsilon(1e-14));
  CHECK(b.reference.K(1, 1) == doctest::Approx(32.561).epsilon(1e-14));
  CHECK(b.reference.K(1, 2) == doctest::Approx(-14.420).epsilon(1e-14));
  CHECK(b.reference.K(2, 2) == doctest::Approx(9.267).epsilon(1e-14));
  CHECK(b.reference.K.isApprox(b.reference.K.transpose(), 0.0));
  CHECK(b.actuator_dof == 1);

  // The experimental substructure: m_e = 29.13 kg, k_e = 1.19e6 N/m = 1.19 kN/mm,
  // c_e = 2 zeta_e sqrt(m_e k_e) N s/m = 1e-6 of it in kN s/mm.
  const double c_e = 2.0 * 0.0097 * std::sqrt(29.13 * 1.19e6);
  CHECK(BenchmarkSpecimen{}.c_e_N_s_per_m() == doctest::Approx(c_e).epsilon(1e-15));
  CHECK(c_e == doctest::Approx(114.22).epsilon(1e-4));
  CHECK(b.experimental.M(0, 0) == doctest::Approx(29.13e-6).epsilon(1e-15));
  CHECK(b.experimental.K(0, 0) == doctest::Approx(1.19).epsilon(1e-15));
  CHECK(b.experimental.C(0, 0) == doctest::Approx(c_e * 1e-6).epsilon(1e-15));
  CHECK(b.experimental.M.cwiseAbs().sum() == b.experimental.M(0, 0));  // nothing but DOF 1
  CHECK(b.experimental.K.cwiseAbs().sum() == b.experimental.K(0, 0));
  CHECK(b.experimental.C.cwiseAbs().sum() == b.experimental.C(0, 0));
}

TEST_CASE("the partition: numerical + experimental == reference; M_n iota == M_ref 1; 5 % in every reference mode") {
  const BenchmarkStructures b = Silva3Structures();
  CHECK(RelDiff(b.numerical.M + b.experimental.M, b.reference.M) < 1e-15);
  CHECK(RelDiff(b.numerical.K + b.experimental.K, b.reference.K) < 1e-15);
  CHECK(RelDiff(b.numerical.C + b.experimental.C, b.reference.C) < 1e-15);
  CHECK(b.numerical.M(0, 0) == doctest::Approx(970.87e-6).epsilon(1e-14));
  CHECK(b.numerical.K(0, 0) == doctest::Approx(26.055 - 1.19).epsilon(1e-14));
  // Only DOF 1 differs from the reference.
  Eigen::MatrixXd dk = b.reference.K - b.numerical.K;
  dk(0, 0) = 0.0;
  CHECK(dk.cwiseAbs().maxCoeff() == 0.0);

  REQUIRE(b.numerical.iota.size() == 3);
  const Eigen::VectorXd lhs = b.numerical.M * b.numerical.iota;
  const Eigen::VectorXd rhs = b.reference.M * Eigen::VectorXd::Ones(3);
  CHECK((lhs - rhs).cwiseAbs().maxCoeff() < 1e-15 * rhs.cwiseAbs().maxCoeff());
  CHECK(b.numerical.iota(0) == doctest::Approx(1000.0 / 970.87).epsilon(1e-15));
  CHECK(b.numerical.iota(1) == 1.0);
  CHECK(b.numerical.iota(2) == 1.0);
  CHECK(b.reference.iota.size() == 0);  // ones

  const Modes modes = ModalAnalysis(b.reference);
  REQUIRE(modes.damping_ratio.size() == 3);
  for (double z : modes.damping_ratio) CHECK(z == doctest::Approx(0.05).epsilon(1e-12));
  for (double f : modes.frequency_hz) CHECK(f > 0.0);
  MESSAGE("reference modes [Hz]: " << modes.frequency_hz[0] << ", " << modes.frequency_hz[1] << ", "
                                   << modes.frequency_hz[2]);

  // Out-of-range specimens are refused.
  CHECK_THROWS_AS(Silva3Structures({-1.0, 1.19e6, 0.0097}), rths::Error);
  CHECK_THROWS_AS(Silva3Structures({29.13, 0.0, 0.0097}), rths::Error);
  CHECK_THROWS_AS(Silva3Structures({29.13, 1.19e6, -0.1}), rths::Error);
  CHECK_THROWS_AS(Silva3Structures({2000.0, 1.19e6, 0.0097}), rths::Error);  // M_n not positive definite
}

TEST_CASE("data/buildings/silva3_*.txt load to Silva3Structures() (to the printed precision), every case") {
  if (std::getenv("RTHS_WRITE_DATA")) {
    WriteSilva3StructureFiles(kData);
    MESSAGE("rewrote " << kData << "silva3_reference_case{1-4}.txt and silva3_numerical_case{1-4}.txt");
  }
  const fs::path dir = TempDir("write");
  WriteSilva3StructureFiles(dir.string());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  for (const BenchmarkCase& c : kBenchmarkCases) {
    CAPTURE(c.number);
    const BenchmarkStructures b = Silva3Structures({}, c);
    const std::string ref_name = "silva3_reference_case" + std::to_string(c.number) + ".txt";
    const std::string num_name = "silva3_numerical_case" + std::to_string(c.number) + ".txt";
    const StructureMatrices ref = LoadStructureFile(kData + ref_name);
    const StructureMatrices num = LoadStructureFile(kData + num_name);
    // %.17g round-trips a double; the masses go through kg (x 1e6 and back), hence 1e-15.
    CHECK(RelDiff(ref.M, b.reference.M) < 1e-15);
    CHECK(RelDiff(ref.K, b.reference.K) < 1e-15);
    CHECK(RelDiff(ref.C, b.reference.C) < 1e-15);
    CHECK(ref.iota.size() == 0);
    CHECK(RelDiff(num.M, b.numerical.M) < 1e-15);
    CHECK(RelDiff(num.K, b.numerical.K) < 1e-15);
    CHECK(RelDiff(num.C, b.numerical.C) < 1e-15);
    REQUIRE(num.iota.size() == 3);
    CHECK(RelDiff(num.iota, b.numerical.iota) < 1e-15);
    // The same files are written again from the function, byte for byte (same platform).
    for (const std::string& name : {ref_name, num_name}) {
      CAPTURE(name);
      CHECK(slurp(dir / name) == slurp(fs::path(kData) / name));
    }
    // Comments say where the numbers come from.
    const std::string text = slurp(fs::path(kData) / num_name);
    CHECK(text.find("Silva, Gomez, Maghareh, Dyke & Spencer") != std::string::npos);
    CHECK(text.find("m_e = 29.13 kg") != std::string::npos);
    CHECK(text.find("M_n iota = M_ref 1") != std::string::npos);
    CHECK(text.find(fmt::format("case {}: floor mass {:g} kg", c.number, c.floor_mass_kg)) != std::string::npos);
  }
}

TEST_CASE("the four cases: floor mass and modal damping of Table 1, the modes the reference code gives") {
  // Modes of the reference code's Case_N.mat (its K differs from the printed 4-digit one by < 5e-6).
  const double modes[4][3] = {{3.612, 15.997, 38.086}, {3.444, 15.252, 36.314}, {3.168, 14.030, 33.404},
                              {3.612, 15.997, 38.086}};
  for (const BenchmarkCase& c : kBenchmarkCases) {
    CAPTURE(c.number);
    const BenchmarkStructures b = Silva3Structures({}, c);
    CHECK(b.reference.M(1, 1) == doctest::Approx(c.floor_mass_kg * 1e-6).epsilon(1e-15));
    const Modes m = ModalAnalysis(b.reference);
    for (int i = 0; i < 3; ++i) {
      CHECK(m.frequency_hz[i] == doctest::Approx(modes[c.number - 1][i]).epsilon(2e-4));
      CHECK(m.damping_ratio[i] == doctest::Approx(c.zeta).epsilon(1e-9));
    }
    // numerical + experimental = reference; the specimen is the same in every case.
    CHECK(RelDiff(b.numerical.K + b.experimental.K, b.reference.K) < 1e-15);
    CHECK(b.experimental.M(0, 0) == doctest::Approx(29.13e-6).epsilon(1e-15));
  }
  CHECK(BenchmarkCaseNumber(3).floor_mass_kg == 1300.0);
  CHECK_THROWS_AS(BenchmarkCaseNumber(5), rths::Error);
  // A perturbed specimen changes K11 and C11 of the numerical substructure only.
  const BenchmarkStructures p = Silva3Structures({29.13, 1.25e6, 0.0097}, kBenchmarkCases[2]);
  const BenchmarkStructures n = Silva3Structures({}, kBenchmarkCases[2]);
  CHECK(p.numerical.K(0, 0) == doctest::Approx(n.numerical.K(0, 0) - 0.06).epsilon(1e-12));
  CHECK(p.reference.K == n.reference.K);
}

TEST_CASE("the iota line: read, written only when not ones, refused when short, carried into the integrator") {
  const fs::path dir = TempDir("iota");
  StructureMatrices m = ShearBuilding({1000.0, 2000.0}, {10.0, 5.0}, 0.05);
  WriteStructureFile((dir / "ones.txt").string(), m, "no iota");
  m.iota = Eigen::VectorXd::Ones(2);
  WriteStructureFile((dir / "ones_explicit.txt").string(), m, "iota of ones: not written");
  m.iota << 1.25, 1.0;
  WriteStructureFile((dir / "iota.txt").string(), m, "with iota");
  CHECK(LoadStructureFile((dir / "ones.txt").string()).iota.size() == 0);
  CHECK(LoadStructureFile((dir / "ones_explicit.txt").string()).iota.size() == 0);
  const StructureMatrices back = LoadStructureFile((dir / "iota.txt").string());
  REQUIRE(back.iota.size() == 2);
  CHECK(back.iota(0) == 1.25);
  CHECK(back.iota(1) == 1.0);
  CHECK(back.IotaOrOnes()(0) == 1.25);
  CHECK(LoadStructureFile((dir / "ones.txt").string()).IotaOrOnes() == Eigen::VectorXd::Ones(2));

  auto error_of = [&](const std::string& text) -> std::string {
    std::ofstream(dir / "bad.txt") << text;
    try {
      LoadStructureFile((dir / "bad.txt").string());
    } catch (const rths::Error& e) {
      return e.what();
    }
    return "";
  };
  const std::string head = "n 2\nM kg\n1 0\n0 1\nK kN/mm\n1 0\n0 1\nC kN*s/mm\n0 0\n0 0\n";
  CHECK(error_of(head + "iota\n1.5\n").find("file ends inside iota") != std::string::npos);
  CHECK(error_of(head + "iota\n1.5 x\n").find("\"x\" is not a number (in iota)") != std::string::npos);
  CHECK(error_of(head + "iota\n1 1 1\n").find("unexpected text after iota") != std::string::npos);
  CHECK(error_of(head + "jota\n1 1\n").find("only an \"iota\" line may follow") != std::string::npos);
  CHECK(error_of(head + "iota 1.5 2\n").empty());  // whitespace-separated: one line or several

  // StructureFromScenario carries it into LinearStructure::iota; CentralDifference uses it for
  // the ground term (p_ground = -Khat^-1 M iota) and the absolute accelerations (x'' + iota a_g).
  StructureConfig st;
  st.kind = StructureKind::kFile;
  st.file = (dir / "iota.txt").string();
  st.actuator_dof = 1;
  st.matrices = LoadStructureFile(st.file);  // the scenario loader's part
  const LinearStructure s = StructureFromScenario(st);
  CHECK(s.iota(0) == 1.25);
  CHECK(s.iota(1) == 1.0);
  const double dt = 1e-3;
  const CentralDifference cd = CentralDifference::Make(s, dt);
  const Eigen::MatrixXd khat = s.M / (dt * dt) + s.C / (2 * dt);
  const Eigen::VectorXd expected = -khat.partialPivLu().solve(s.M * s.iota);
  CHECK((cd.p_ground - expected).cwiseAbs().maxCoeff() < 1e-12 * expected.cwiseAbs().maxCoeff());
  StructureState state = MakeState(cd);
  Advance(cd, &state, 1000.0, 0.0);  // from rest: x_1 = p_ground a_g, relative acc at 0 = x_1 / dt^2
  CHECK(state.abs_acc_prev(0) == doctest::Approx(state.acc_prev(0) + 1.25 * 1000.0).epsilon(1e-12));
  CHECK(state.abs_acc_prev(1) == doctest::Approx(state.acc_prev(1) + 1000.0).epsilon(1e-12));
  st.file = (dir / "ones.txt").string();
  st.matrices = LoadStructureFile(st.file);
  CHECK(StructureFromScenario(st).iota == Eigen::VectorXd::Ones(2));
}
