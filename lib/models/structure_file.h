#pragma once
/// @file Structures as text files a user can replace (docs/structures.md), shear-building
/// construction with modal damping, and modal analysis.
///
/// File format (whitespace separated; '#' starts a comment):
///     # rths structure v1
///     n 9
///     M kg              then n rows of n values: mass matrix [kg]
///     K kN/mm           then n rows of n values: stiffness [kN/mm]
///     C kN*s/mm         then n rows of n values: damping [kN s/mm]
///     iota              optional, then n values: ground influence vector [-] (default: ones)
/// The loader converts M to project units (kN s^2/mm = kg * 1e-6).
///
/// iota enters the equation of motion as the ground load -M iota a_g (structure.h). A shear
/// building has iota = 1. A partitioned numerical substructure may need another: when the
/// measured force carries only the specimen's relative inertia m_e x''_1 (its actuator reacts
/// against the ground), the specimen mass's ground inertia -m_e a_g stays on the numerical side, so
/// M_n iota = M_ref 1 (the benchmark partition, data/buildings/silva3_numerical_case1.txt:
/// iota_1 = M_ref,11 / M_n,11). Note that CentralDifference also reports the absolute
/// accelerations as x'' + iota a_g.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/names.h"
#include "models/integrator_config.h"
#include "models/nonlinear_building.h"
#include "models/structure_integrator.h"
#include "models/story_spring.h"
#include "models/structure.h"
#include "signal/history.h"

namespace rths::models {

/// Where the reference displacement comes from (StructureConfig::mode).
enum class StructureMode { kRths, kPredefined };
inline constexpr std::array<Named<StructureMode>, 2> kStructureModeNames = {
    {{StructureMode::kRths, "rths"}, {StructureMode::kPredefined, "predefined"}}};
/// What the numerical substructure is (StructureConfig::kind).
enum class StructureKind { kSdof, kFile };
inline constexpr std::array<Named<StructureKind>, 2> kStructureKindNames = {
    {{StructureKind::kSdof, "sdof"}, {StructureKind::kFile, "file"}}};
/// How the integrator gets r', r'', r''' in predefined mode (StructureConfig::derivatives).
enum class Derivatives { kExtrapolated, kCentral };
inline constexpr std::array<Named<Derivatives>, 2> kDerivativesNames = {
    {{Derivatives::kExtrapolated, "extrapolated"}, {Derivatives::kCentral, "central"}}};

/// M [kN s^2/mm], K [kN/mm], C [kN s/mm], and the ground influence vector iota [-] (empty: ones).
struct StructureMatrices {
  Eigen::MatrixXd M, K, C;  ///< for a shear-building file: K the initial stiffness, C from it
  Eigen::VectorXd iota;  ///< n entries, or empty for ones (a shear building)
  /// A shear-building file's story springs, story 1 first (empty for a matrix file).
  std::vector<SpringParams> springs;
  /// iota if it is set, else ones (n = M.rows()).
  Eigen::VectorXd IotaOrOnes() const;
  /// Same sizes and the same values (empty matrices are equal).
  bool operator==(const StructureMatrices& o) const;
};

/// Numerical substructure (procs/integrator). Config is parsed and every file it names is read
/// once, at the edge: `file` and `reference_file` stay the paths the scenario names (ToToml writes
/// them, the scenario's hash is of its text); `matrices` and `reference` hold what they contain,
/// filled by the scenario loader (scenario::ReadReferencedFiles). Components take the data, never
/// the paths.
struct StructureConfig {
  StructureMode mode = StructureMode::kRths;  ///< "rths" (central difference, Eqs. 1-3) | "predefined" (r from a history)
  /// mode = "rths": "sdof" (mass, frequency, damping below) | "file" (M, K, C from `file`, a
  /// structure file: docs/structures.md; e.g. data/buildings/ohtori9_ns.txt).
  StructureKind kind = StructureKind::kSdof;
  /// mode = "rths": how the substructure is stepped (models/integrator_config.h): structure.integrator
  /// ("central_difference", the lockstep's own Eqs. 1-3; "rk4_unit_delay", the RTHS benchmark's
  /// reference-code loop, with the criteria's reference integrated continuously too; "cr",
  /// "alpha_os", "newmark_implicit") and its options structure.substeps, structure.alpha_os_alpha,
  /// structure.newton_iterations.
  IntegratorConfig integrator{};
  std::string file;           ///< kind = "file": path, relative to the scenario file's folder
  /// mode = "rths", kind = "file", optional: the monolithic reference structure of a partitioned
  /// test (a structure file with as many DOFs as `file`; e.g. data/buildings/silva3_reference_case1.txt),
  /// integrated offline under the run's ground acceleration for the benchmark criteria J1-J9
  /// (participants/benchmark_run.h). "" for none. Relative to the scenario file's folder.
  std::string reference_file;
  int actuator_dof = 1;       ///< kind = "file": DOF the specimen acts on, 1-based (1 = first story)
  /// kind = "file" with a reference_file and plant.kind = "benchmark": the numerical substructure is
  /// the reference minus the plant's experimental substructure (plant.benchmark m_e_kg, k_e_N_per_m,
  /// zeta_e) at actuator_dof (models::SubtractSpecimen), as the benchmark's reference code builds it
  /// for the plant it runs, a perturbed one included; `file` is then not read.
  bool subtract_specimen = false;
  // kind = "sdof":
  double mass_kg = 20000.0;          ///< (0, 1e9]
  double frequency_hz = 5.0;         ///< natural frequency (0, 1/(pi dt)) -- central-difference limit omega dt < 2
  double damping_ratio = 0.02;       ///< [0, 1)
  double specimen_count = 1.0;       ///< measured force multiplier (18 dampers act as one) [0, 1000]; 0: none acts
  /// kind = "sdof": the story spring ([structure.spring]; models/story_spring.h): "linear" (today's
  /// K = m w^2), "bouc_wen" or "bilinear" with the initial stiffness k = m w^2 from mass_kg and
  /// frequency_hz (spring.k_kN_per_mm is set from them; the file does not give it), the damping
  /// 2 zeta m w at that initial stiffness.
  SpringParams spring{};
  signal::SignalSpec ground{};               ///< ground acceleration [mm/s^2]
  // mode = "predefined": the desired displacement itself [mm].
  signal::SignalSpec desired{signal::SignalKind::kBlwn, 5.0, 2.78, 1, 2.0, "", 0.0, 1.0, 0.5};
  /// How the integrator gets r', r'', r''' in predefined mode: "extrapolated" (Eqs. 20-22, the
  /// causal RTHS path) | "central" (offline, non-causal central differences of the known record).
  Derivatives derivatives = Derivatives::kExtrapolated;
  /// mode = "rths", kind = "file": the matrices of `file` (LoadStructureFile); empty otherwise.
  StructureMatrices matrices{};
  /// The matrices of `reference_file`; empty if there is none.
  StructureMatrices reference{};
  /// A hysteretic spring somewhere (mode "rths"): the SDOF's, or a story of a shear-building file.
  bool Nonlinear() const {
    if (mode != StructureMode::kRths) return false;
    if (kind == StructureKind::kSdof) return spring.kind != SpringKind::kLinear;
    for (const SpringParams& p : matrices.springs)
      if (p.kind != SpringKind::kLinear) return true;
    return false;
  }
  /// Stepped by models::StructureIntegrator (a NonlinearBuilding), not by today's linear paths: a
  /// hysteretic spring, cr, alpha_os, newmark_implicit, or central difference with sub-steps.
  bool Stepped() const {
    const IntegratorKind k = integrator.kind;
    return mode == StructureMode::kRths &&
           (Nonlinear() || k == IntegratorKind::kCr || k == IntegratorKind::kAlphaOs ||
            k == IntegratorKind::kNewmarkImplicit || (k == IntegratorKind::kCentralDifference && integrator.substeps > 1));
  }
  bool operator==(const StructureConfig&) const = default;
};

/// Reads a structure file; throws rths::Error naming the file, line and problem (missing or
/// malformed matrix, wrong size, non-symmetric M or K, M not positive definite, an iota line
/// without n values). iota is left empty when the file has no iota line.
///
/// Or a shear building with a spring per story (docs/structures.md "A shear building with story
/// springs"), after "n N":
///     floors kg            then n floor masses [kg], floor 1 first
///     story KIND key=value ...   n lines, story 1 (ground to floor 1) first; KIND linear |
///                          bouc_wen | bilinear; keys of SpringParams (k_kN_per_mm required)
///     damping modal ZETA | damping rayleigh MODE_I ZETA_I MODE_J ZETA_J   (of the initial stiffness)
/// M, K (the initial stiffness), C are filled from them and `springs` holds the stories; an error
/// names the file, line, story and key.
StructureMatrices LoadStructureFile(const std::string& path);
/// Writes a structure file (masses back in kg), with `comment` lines after the header; the iota
/// line only if m.iota is set and not all ones.
void WriteStructureFile(const std::string& path, const StructureMatrices& m, const std::string& comment);

/// Damping matrix with the ratio zeta in every mode of (M, K):
/// C = M Phi diag(2 zeta w_i) Phi^T M, Phi the mass-normalised modes (Phi^T M Phi = I), w_i their
/// natural circular frequencies [rad/s]; symmetrised. Units follow M and K (kN s^2/mm, kN/mm ->
/// kN s/mm).
Eigen::MatrixXd ModalDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double zeta);

/// A lumped-mass shear building: floor masses [kg] (floor 1 first), story stiffnesses [kN/mm]
/// (story 1 between the ground and floor 1), and damping ratio zeta in every mode:
/// C = M Phi diag(2 zeta w_i) Phi^T M with Phi mass-normalised (Phi^T M Phi = I).
StructureMatrices ShearBuilding(const std::vector<double>& floor_masses_kg,
                                const std::vector<double>& story_stiffness_kN_per_mm, double zeta);

/// Undamped modes: natural frequencies [Hz], ascending, and the modal damping ratios
/// zeta_i = (phi_i^T C phi_i) / (2 w_i) of mass-normalised modes.
struct Modes {
  std::vector<double> frequency_hz;
  std::vector<double> damping_ratio;
};
Modes ModalAnalysis(const StructureMatrices& m);

/// The numerical substructure a scenario describes: the SDOF of [structure], or st.matrices (the
/// structure file's, with its iota carried into LinearStructure::iota) with the specimen on
/// structure.actuator_dof (1-based). Throws rths::Error naming "structure.file" if the matrices
/// were not read, or "structure.actuator_dof" if it exceeds their DOFs (the loader checks both).
LinearStructure StructureFromScenario(const models::StructureConfig& st);

/// The numerical substructure as a NonlinearBuilding: the SDOF of [structure] with its
/// [structure.spring] (one story, initial stiffness k = m w^2, w = 2 pi frequency_hz, damping
/// 2 zeta m w at it), or a shear-building file's floors, story springs and damping; the specimen at
/// structure.actuator_dof times specimen_count. Throws rths::Error naming the key ("structure.file"
/// for a matrix file: it has no story springs).
NonlinearBuilding NonlinearFromScenario(const models::StructureConfig& st);
/// The integrator of a structure that StructureConfig::Stepped() says is stepped by
/// models::StructureIntegrator: NonlinearFromScenario(st) with st.integrator at dt_s [s].
/// Throws rths::Error (the integrator's checks, e.g. central difference's stability limit).
StructureIntegrator SteppedIntegratorFromScenario(const models::StructureConfig& st, double dt_s);

}  // namespace rths::models
