#include "models/benchmark_structures.h"

#include <cmath>
#include <filesystem>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

namespace {
constexpr double kKgToProject = 1e-6;     // kg -> kN s^2/mm
constexpr double kNPerMToProject = 1e-6;  // N/m -> kN/mm (1e-3 kN per 1e3 mm)
constexpr double kNsPerMToProject = 1e-6; // N s/m -> kN s/mm

bool PositiveDefinite(const Eigen::MatrixXd& a) { return Eigen::LLT<Eigen::MatrixXd>(a).info() == Eigen::Success; }

std::string FrequencyList(const StructureMatrices& m) {
  const Modes modes = ModalAnalysis(m);
  std::string out;
  for (std::size_t i = 0; i < modes.frequency_hz.size(); ++i) {
    out += fmt::format("{}{:.4f} Hz (zeta {:.4f})", i ? ", " : "", modes.frequency_hz[i], modes.damping_ratio[i]);
  }
  return out;
}
}  // namespace

double BenchmarkSpecimen::c_e_N_s_per_m() const { return 2.0 * zeta_e * std::sqrt(m_e_kg * k_e_N_per_m); }

const BenchmarkCase& BenchmarkCaseNumber(int number) {
  if (number < 1 || number > 4) throw Error("benchmark case", fmt::format("{} is out of range [1, 4]", number));
  return kBenchmarkCases[number - 1];
}

StructureMatrices SubtractSpecimen(const StructureMatrices& reference, const BenchmarkSpecimen& e, int dof) {
  if (!(e.m_e_kg > 0.0) || !std::isfinite(e.m_e_kg))
    throw Error("specimen: m_e_kg", fmt::format("{} is out of range (0, inf)", e.m_e_kg));
  if (!(e.k_e_N_per_m > 0.0) || !std::isfinite(e.k_e_N_per_m))
    throw Error("specimen: k_e_N_per_m", fmt::format("{} is out of range (0, inf)", e.k_e_N_per_m));
  if (!(e.zeta_e >= 0.0) || !std::isfinite(e.zeta_e))
    throw Error("specimen: zeta_e", fmt::format("{} is out of range [0, inf)", e.zeta_e));
  const auto n = reference.M.rows();
  if (dof < 1 || dof > n) throw Error("specimen: dof", fmt::format("{} is out of range [1, {}]", dof, n));
  const auto d = dof - 1;
  StructureMatrices out = reference;
  out.M(d, d) -= e.m_e_kg * kKgToProject;
  out.K(d, d) -= e.k_e_N_per_m * kNPerMToProject;
  out.C(d, d) -= e.c_e_N_s_per_m() * kNsPerMToProject;
  if (!PositiveDefinite(out.M) || !PositiveDefinite(out.K))
    throw Error("specimen", "subtracting the experimental substructure leaves M_n or K_n not positive definite");
  const Eigen::VectorXd load = reference.M * reference.IotaOrOnes();  // M_ref iota_ref
  const bool diagonal = out.M.isDiagonal(0.0);
  out.iota = diagonal ? Eigen::VectorXd(load.cwiseQuotient(out.M.diagonal())) : Eigen::VectorXd(out.M.ldlt().solve(load));
  return out;
}

BenchmarkStructures Silva3Structures(const BenchmarkSpecimen& e, const BenchmarkCase& c) {
  BenchmarkStructures b;
  StructureMatrices& r = b.reference;
  r.M = Eigen::MatrixXd::Identity(3, 3) * (c.floor_mass_kg * kKgToProject);
  Eigen::Matrix3d k_si;
  k_si << 2.6055, -2.3134, 0.5937,  //
      -2.3134, 3.2561, -1.4420,     //
      0.5937, -1.4420, 0.9267;
  r.K = (1e7 * kNPerMToProject) * Eigen::MatrixXd(k_si);
  r.C = ModalDampingMatrix(r.M, r.K, c.zeta);

  StructureMatrices& x = b.experimental;
  x.M = x.K = x.C = Eigen::MatrixXd::Zero(3, 3);
  x.M(0, 0) = e.m_e_kg * kKgToProject;
  x.K(0, 0) = e.k_e_N_per_m * kNPerMToProject;
  x.C(0, 0) = e.c_e_N_s_per_m() * kNsPerMToProject;

  b.numerical = SubtractSpecimen(r, e, 1);
  b.actuator_dof = 1;
  return b;
}

namespace {
const char* kSource =
    "RTHS benchmark problem: Silva, Gomez, Maghareh, Dyke & Spencer, Mech. Syst. Signal Process. 2020\n"
    "(docs/benchmark.md). Written by models::WriteSilva3StructureFiles (lib/models/benchmark_structures.cpp);\n"
    "tests/models/benchmark_structures_test.cpp checks this file against it (RTHS_WRITE_DATA=1 rewrites it).\n";

std::string CaseText(const BenchmarkCase& c) {
  return fmt::format("case {}: floor mass {:g} kg, {:g} % damping in every mode", c.number, c.floor_mass_kg,
                     100.0 * c.zeta);
}
}  // namespace

void WriteSilva3NumericalFile(const std::string& path, const BenchmarkCase& c, const BenchmarkSpecimen& e,
                              const std::string& note) {
  const BenchmarkStructures b = Silva3Structures(e, c);
  const double c_e = e.c_e_N_s_per_m();
  const double m = c.floor_mass_kg;
  const std::string comment =
      fmt::format("Numerical substructure of the benchmark, {}: the reference\n"
                  "(silva3_reference_case{}.txt) minus the experimental substructure at floor 1 (DOF 1, the actuator's).\n",
                  CaseText(c), c.number) +
      (note.empty() ? "" : note + "\n") + kSource +
      fmt::format("Experimental substructure: m_e = {:g} kg, k_e = {:.9g} N/m = {:.9g} kN/mm,\n"
                  "  zeta_e = {:g}, c_e = 2 zeta_e sqrt(m_e k_e) = {:.6g} N s/m = {:.6g} kN*s/mm.\n",
                  e.m_e_kg, e.k_e_N_per_m, e.k_e_N_per_m * kNPerMToProject, e.zeta_e, c_e, c_e * kNsPerMToProject) +
      fmt::format("M11 = {:g} - {:g} = {:g} kg; K11 = K_ref,11 - k_e; C11 = C_ref,11 - c_e; every other entry\n"
                  "  is the reference's.\n",
                  m, e.m_e_kg, m - e.m_e_kg) +
      fmt::format("iota: the measured force carries only m_e x''_1 (relative), so the specimen mass's ground\n"
                  "  inertia stays here: M_n iota = M_ref 1, iota_1 = {:g} / {:g} = {:.9g}.\n"
                  "  (The integrator's absolute acceleration of floor 1, x''_1 + iota_1 a_g, is therefore off\n"
                  "  by (iota_1 - 1) a_g; nothing in the benchmark uses it.)\n",
                  m, m - e.m_e_kg, b.numerical.iota(0)) +
      "Modes (of this substructure alone): " + FrequencyList(b.numerical) + ".\n" +
      fmt::format("Scenario: structure.kind = \"file\", actuator_dof = 1, specimen_count = 1,\n"
                  "  reference_file = \"silva3_reference_case{}.txt\" (in data/buildings/) for the criteria J1-J9.",
                  c.number);
  WriteStructureFile(path, b.numerical, comment);
}

void WriteSilva3StructureFiles(const std::string& dir) {
  const std::filesystem::path d(dir);
  for (const BenchmarkCase& c : kBenchmarkCases) {
    const BenchmarkStructures b = Silva3Structures({}, c);
    const std::string reference_comment =
        fmt::format("Reference (monolithic) structure of the benchmark, 3 stories, {}.\n", CaseText(c)) + kSource +
        fmt::format("M = {:g} I3 kg (the benchmark's Table 1).\n", c.floor_mass_kg) +
        "K = 1e7 x [[2.6055, -2.3134, 0.5937], [-2.3134, 3.2561, -1.4420], [0.5937, -1.4420, 0.9267]] N/m\n"
        "  = 10 x the same matrix in kN/mm (1 N/m = 1e-6 kN/mm); the same in every case.\n" +
        fmt::format("C: {:g} % damping in every mode, C = M Phi diag(2 zeta w_i) Phi^T M, Phi mass-normalised\n"
                    "  (models::ModalDampingMatrix).\n",
                    100.0 * c.zeta) +
        "Modes: " + FrequencyList(b.reference) + ".\n" + "Displacements relative to the ground; iota = 1 (no iota line).";
    WriteStructureFile((d / fmt::format("silva3_reference_case{}.txt", c.number)).string(), b.reference,
                       reference_comment);
    WriteSilva3NumericalFile((d / fmt::format("silva3_numerical_case{}.txt", c.number)).string(), c, {});
  }
}

}  // namespace rths::models
