#pragma once
/// @file The structure of the RTHS benchmark problem (Silva, Gomez, Maghareh, Dyke & Spencer,
/// Mech. Syst. Signal Process. 2020; docs/benchmark.md) in its four partitioning cases, and its
/// partition into a numerical and an experimental substructure, as structure matrices in project
/// units (mm, kN, s; mass kN s^2/mm = kg * 1e-6). The benchmark's constants are SI: they are
/// converted here, once.
///
/// Reference (monolithic) structure, 3 stories, SI, case c (the benchmark's Table 1; its reference
/// code's Reference_def.m):
///
///     M_ref = m_c I3,  m_c = 1000 / 1100 / 1300 / 1000 kg  (cases 1 / 2 / 3 / 4)
///     K_ref = 1e7 [[2.6055, -2.3134, 0.5937], [-2.3134, 3.2561, -1.4420], [0.5937, -1.4420, 0.9267]] N/m
///     C_ref = M Phi diag(2 zeta_c w_i) Phi^T M,  zeta_c = 5 / 4 / 3 / 3 % in every mode (Phi mass-normalised)
///
/// 1 N/m = 1e-6 kN/mm, so K_ref = 10 [[...]] kN/mm. The experimental substructure (the same in
/// every case) sits at floor 1: m_e = 29.13 kg, k_e = 1.19e6 N/m, zeta_e = 0.0097,
/// c_e = 2 zeta_e sqrt(m_e k_e). The numerical substructure is the reference minus it at DOF 1
/// (the reference code subtracts the specimen it runs, perturbed k_e and c_e included):
///
///     M_n = M_ref - m_e e1 e1^T,  C_n = C_ref - c_e e1 e1^T,  K_n = K_ref - k_e e1 e1^T.
///
/// Ground inertia: the reference is loaded by -M_ref 1 a_g. The measured force carries only the
/// specimen's relative motion, f = m_e x''_1 + c_e x'_1 + k_e x_1 (the actuator reacts against the
/// ground), so the numerical side keeps the specimen's ground inertia: M_n iota = M_ref 1, i.e.
/// iota_i = (M_ref 1)_i / M_n,ii for the diagonal masses here (iota_1 = 1000 / 970.87).
/// Then M_n x'' + C_n x' + K_n x + e1 f = -M_n iota a_g is the reference's equation of motion.
#include <string>

#include "models/structure_file.h"

namespace rths::models {

/// The experimental substructure of the benchmark, case 1 (SI, the benchmark's nominal values).
struct BenchmarkSpecimen {
  double m_e_kg = 29.13;         ///< mass [kg] (> 0)
  double k_e_N_per_m = 1.19e6;   ///< stiffness [N/m] (> 0)
  double zeta_e = 0.0097;        ///< damping ratio [-] (>= 0)
  /// c_e = 2 zeta_e sqrt(m_e k_e) [N s/m].
  double c_e_N_s_per_m() const;
};

/// One partitioning case of the benchmark: the reference structure's floor mass and modal damping.
struct BenchmarkCase {
  int number = 1;                ///< 1 .. 4
  double floor_mass_kg = 1000.0; ///< every floor [kg]
  double zeta = 0.05;            ///< every mode [-]
};
/// The benchmark's four cases (Table 1 of Silva et al. 2020).
inline constexpr BenchmarkCase kBenchmarkCases[4] = {
    {1, 1000.0, 0.05}, {2, 1100.0, 0.04}, {3, 1300.0, 0.03}, {4, 1000.0, 0.03}};
/// kBenchmarkCases[number - 1]; throws rths::Error unless number is 1 .. 4.
const BenchmarkCase& BenchmarkCaseNumber(int number);

/// The benchmark's reference structure and its partition, in project units.
struct BenchmarkStructures {
  StructureMatrices reference;     ///< M_ref, K_ref, C_ref; iota empty (ones)
  StructureMatrices experimental;  ///< m_e, c_e, k_e at (0, 0), zeros elsewhere; iota empty
  StructureMatrices numerical;     ///< reference - experimental; iota with M_n iota = M_ref 1
  int actuator_dof = 1;            ///< the experimental substructure's floor (1-based)
};

/// The benchmark's 3-story reference structure of case `c` and its partition (the formulas of the
/// file comment) for the experimental substructure `e`. Throws rths::Error if e's values are out of
/// range (m_e, k_e > 0, zeta_e >= 0, all finite) or leave M_n or K_n not positive definite.
BenchmarkStructures Silva3Structures(const BenchmarkSpecimen& e = {}, const BenchmarkCase& c = kBenchmarkCases[0]);

/// The numerical substructure of a partitioned test: `reference` minus the specimen `e` at DOF
/// `dof` (1-based), in project units, as the benchmark's reference code builds it for the plant it
/// runs (a perturbed k_e included): M_n = M_ref - m_e e_d e_d^T, C_n = C_ref - c_e e_d e_d^T,
/// K_n = K_ref - k_e e_d e_d^T, and iota with M_n iota = M_ref iota_ref (the specimen mass's ground
/// inertia stays on the numerical side; element-wise for a diagonal M_n). Throws rths::Error if
/// e's values are out of range, dof is not a DOF of `reference`, or M_n or K_n is not positive definite.
StructureMatrices SubtractSpecimen(const StructureMatrices& reference, const BenchmarkSpecimen& e, int dof);

/// Writes the numerical substructure of case `c` for specimen `e` to `path`, with comments saying
/// where every number comes from (`note`: one more line, e.g. which perturbed plant it is for).
/// Throws rths::Error if the file cannot be written.
void WriteSilva3NumericalFile(const std::string& path, const BenchmarkCase& c, const BenchmarkSpecimen& e,
                              const std::string& note = "");

/// Writes `dir`/silva3_reference_caseN.txt and `dir`/silva3_numerical_caseN.txt, N = 1 .. 4, from
/// Silva3Structures() (the repository's copies are in data/buildings/;
/// tests/models/benchmark_structures_test.cpp checks them against this function).
/// Throws rths::Error if a file cannot be written.
void WriteSilva3StructureFiles(const std::string& dir);

}  // namespace rths::models
