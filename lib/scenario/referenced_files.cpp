/// @file Every file a scenario names, read once, at the edge (ReadReferencedFiles): the structure
/// file, the benchmark's reference structure, and the ground or desired records of kind "file".
/// Components get this data, never the paths.
#include <string>

#include <fmt/format.h>

#include "core/names.h"
#include "models/benchmark_structures.h"
#include "models/marths_files.h"
#include "models/marths_structure.h"
#include "scenario/walk.h"

namespace rths::scenario {

namespace {

/// structure.file and structure.reference_file (mode "rths", kind "file"): the matrices, the
/// reference's DOFs against the structure's, and structure.actuator_dof against them.
void ReadStructureFiles(const std::string& path, const detail::Check& check, const models::PlantConfig& plant,
                        models::StructureConfig* st) {
  st->matrices = {};
  st->reference = {};
  const bool has_file = st->mode == models::StructureMode::kRths && st->kind == models::StructureKind::kFile;
  if (!st->reference_file.empty()) {
    try {
      st->reference = models::LoadStructureFile(detail::ResolveFile(path, st->reference_file).string());
    } catch (const Error& e) {
      check.Fail("structure.reference_file", e.what());
    }
  }
  if (!has_file) return;
  const std::string file = detail::ResolveFile(path, st->subtract_specimen ? st->reference_file : st->file).string();
  if (st->subtract_specimen) {
    const models::BenchmarkPlantParams& p = plant.benchmark.params;
    try {
      st->matrices = models::SubtractSpecimen(st->reference, {p.m_e_kg, p.k_e_N_per_m, p.zeta_e}, st->actuator_dof);
    } catch (const Error& e) {
      check.Fail("structure.subtract_specimen", fmt::format("{}: {}", e.where(), e.problem()));
    }
    return;
  }
  st->matrices = models::LoadStructureFile(file);  // its own errors name the file and line
  if (st->Stepped() && st->matrices.springs.empty())
    check.Fail("structure.integrator",
               fmt::format("{}{} needs story springs: {} is a matrix file (M, K, C); give a shear-building file "
                           "(floors, story lines: docs/structures.md) or use central_difference or rk4_unit_delay",
                           NameOf(models::kIntegratorKindNames, st->integrator.kind),
                           st->integrator.substeps > 1 ? " with substeps" : "", st->file));
  if (st->integrator.kind == models::IntegratorKind::kRk4UnitDelay && st->Nonlinear())
    check.Fail("structure.integrator", "rk4_unit_delay runs linear structures only (the benchmark's reference-code "
                                       "loop): choose central_difference, cr, alpha_os or newmark_implicit");
  const auto dofs = st->matrices.M.rows();
  if (!st->reference_file.empty() && st->reference.M.rows() != dofs) {
    check.Fail("structure.reference_file", fmt::format("{} has {} DOFs but structure.file ({}) has {}: they must match",
                                                       st->reference_file, st->reference.M.rows(), st->file, dofs));
  }
  if (st->actuator_dof > dofs) {
    throw Error(path + ": structure.actuator_dof",
                fmt::format("{} is out of range [1, {}] ({} has {} DOFs)", st->actuator_dof, dofs, file, dofs));
  }
}

/// [marths] (when enabled): the matrices, RoDeAC's parameters and the ground record; each reader's
/// errors name the file and line.
void ReadMarthsFiles(const std::string& path, const detail::Check& check, control::MarthsConfig* m) {
  m->files = {};
  m->ground = {};
  if (!m->enabled) return;
  auto file = [&](const std::string& f) { return detail::ResolveFile(path, f).string(); };
  m->files.K_ref = models::marths::ReadMatrixCsv(file(m->reference_k_file));
  m->files.M_ref = models::marths::ReadMatrixCsv(file(m->reference_m_file));
  m->files.rodeac = models::marths::ReadRodeacParameters(file(m->rodeac_file));
  m->ground = signal::ReadHistoryFile(file(m->ground_file), 0.0);
  const auto n = m->files.K_ref.rows();
  if (m->files.K_ref.cols() != n || m->files.M_ref.rows() != n || m->files.M_ref.cols() != n) {
    check.Fail("marths.reference_m_file",
               fmt::format("the reference matrices must be square and of one size (29 x 29 in the benchmark): K is "
                           "{} x {}, M is {} x {}",
                           m->files.K_ref.rows(), m->files.K_ref.cols(), m->files.M_ref.rows(),
                           m->files.M_ref.cols()));
  }
  if (const std::string why = models::marths::FrameDofsProblem(m->dofs, static_cast<int>(n)); !why.empty()) {
    check.Fail("marths.interface_dofs", fmt::format("(with story_dofs, ground_dofs; the matrices of {}): {}",
                                                    m->reference_k_file, why));
  }
}

}  // namespace

void ReadReferencedFiles(Scenario* s) {
  const detail::Check check(detail::DisplayName(s->path));
  ReadStructureFiles(s->path, check, s->plant, &s->structure);
  ReadMarthsFiles(s->path, check, &s->marths);
  for (signal::SignalSpec* signal : {&s->structure.ground, &s->structure.desired}) {
    signal->record = {};
    if (signal->kind != signal::SignalKind::kFile) continue;
    // The file's own errors name it and the line (signal::LoadHistory's messages).
    signal->record = signal::ReadHistoryFile(detail::ResolveFile(s->path, signal->file).string(), signal->file_dt_s);
  }
}

}  // namespace rths::scenario
