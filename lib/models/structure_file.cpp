#include "models/structure_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "core/error.h"
#include "models/nonlinear_building.h"

namespace rths::models {

namespace {
constexpr double kKgToProject = 1e-6;  // kg -> kN s^2/mm

/// Non-comment tokens with their line numbers.
struct Tokens {
  std::vector<std::string> words;
  std::vector<int> lines;
  std::size_t next = 0;
};

Tokens Tokenize(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot open the structure file");
  Tokens t;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream ss(line);
    for (std::string w; ss >> w;) {
      t.words.push_back(w);
      t.lines.push_back(n);
    }
  }
  return t;
}

std::string Where(const std::string& path, const Tokens& t) {
  const int line = t.next < t.lines.size() ? t.lines[t.next] : (t.lines.empty() ? 0 : t.lines.back());
  return fmt::format("{}:{}", path, line);
}

double Number(const std::string& path, Tokens* t, const char* what) {
  if (t->next >= t->words.size()) throw Error(Where(path, *t), fmt::format("file ends inside {}", what));
  const std::string& w = t->words[t->next];
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(w, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != w.size() || !std::isfinite(v)) {
    throw Error(Where(path, *t), fmt::format("\"{}\" is not a number (in {})", w, what));
  }
  ++t->next;
  return v;
}

void Expect(const std::string& path, Tokens* t, const std::string& word, const std::string& unit) {
  if (t->next >= t->words.size() || t->words[t->next] != word) {
    throw Error(Where(path, *t), fmt::format("expected \"{} {}\"", word, unit));
  }
  ++t->next;
  if (!unit.empty()) {
    if (t->next >= t->words.size() || t->words[t->next] != unit) {
      throw Error(Where(path, *t), fmt::format("matrix {} must be given in {}", word, unit));
    }
    ++t->next;
  }
}

Eigen::MatrixXd Matrix(const std::string& path, Tokens* t, int n, const char* name) {
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) m(i, j) = Number(path, t, name);
  }
  return m;
}

void CheckSymmetric(const std::string& path, const Eigen::MatrixXd& a, const char* name) {
  const double tol = 1e-9 * std::max(1.0, a.cwiseAbs().maxCoeff());
  if ((a - a.transpose()).cwiseAbs().maxCoeff() > tol) throw Error(path, fmt::format("{} is not symmetric", name));
}
}  // namespace

namespace {

/// One "story KIND key=value ..." line's spring: its words up to the next "story" or "damping".
SpringParams StoryLine(const std::string& path, Tokens* t, int story) {
  const std::string where = Where(path, *t);
  if (t->next >= t->words.size() || t->words[t->next] != "story")
    throw Error(where, fmt::format("expected story {}: \"story KIND key=value ...\" (one line per story, story 1 first)", story));
  ++t->next;
  SpringParams p;
  const std::string kind = t->next < t->words.size() ? t->words[t->next++] : "";
  p.kind = ParseName(kSpringKindNames, kind, fmt::format("{}: story {}: kind", where, story));
  const std::array<std::pair<const char*, double*>, 10> keys = {{{"k_kN_per_mm", &p.k_kN_per_mm}, {"alpha", &p.alpha},
                                                                 {"x_y_mm", &p.x_y_mm}, {"n", &p.n}, {"beta", &p.beta},
                                                                 {"gamma", &p.gamma}, {"delta_nu", &p.delta_nu},
                                                                 {"delta_eta", &p.delta_eta}, {"b", &p.b},
                                                                 {"f_y_kN", &p.f_y_kN}}};
  bool has_k = false;
  while (t->next < t->words.size() && t->words[t->next] != "story" && t->words[t->next] != "damping") {
    const std::string w = t->words[t->next];
    const std::size_t eq = w.find('=');
    const auto key = std::find_if(keys.begin(), keys.end(), [&](const auto& k) { return w.substr(0, eq) == k.first; });
    if (eq == std::string::npos || key == keys.end()) {
      std::string names;
      for (const auto& k : keys) names += std::string(names.empty() ? "" : ", ") + k.first;
      throw Error(Where(path, *t), fmt::format("story {}: \"{}\" is not key=value with a key of {}", story, w, names));
    }
    t->words[t->next] = w.substr(eq + 1);  // the value, read as a number where it stands
    *key->second = Number(path, t, key->first);
    has_k = has_k || key->second == &p.k_kN_per_mm;
  }
  if (!has_k) throw Error(where, fmt::format("story {}: k_kN_per_mm=... (its initial stiffness) is missing", story));
  try {
    p.Validate();
  } catch (const Error& e) {
    throw Error(where, fmt::format("story {}: {}: {}", story, e.where(), e.problem()));
  }
  return p;
}

/// The shear-building form after "n N": floor masses, a spring per story, the damping.
StructureMatrices ShearBuildingFile(const std::string& path, Tokens* t, int n) {
  Expect(path, t, "floors", "kg");
  std::vector<double> masses(static_cast<std::size_t>(n));
  for (double& m : masses) {
    const std::string where = Where(path, *t);
    m = Number(path, t, "floors");
    if (!(m > 0.0 && m <= 1e9)) throw Error(where, fmt::format("floor mass {} kg is out of range (0, 1e9]", m));
  }
  StructureMatrices out;
  for (int i = 1; i <= n; ++i) out.springs.push_back(StoryLine(path, t, i));
  const std::string where = Where(path, *t);
  Expect(path, t, "damping", "");
  out.M = MassMatrix(masses);
  out.K = InitialStiffness(out.springs);
  const std::string how = t->next < t->words.size() ? t->words[t->next++] : "";
  try {
    if (how == "modal") {
      const double zeta = Number(path, t, "damping modal ZETA");
      if (!(zeta >= 0.0 && zeta < 1.0)) throw Error("zeta", fmt::format("{} is out of range [0, 1)", zeta));
      out.C = ModalDampingMatrix(out.M, out.K, zeta);
    } else if (how == "rayleigh") {
      const int i = static_cast<int>(Number(path, t, "damping rayleigh MODE_I"));
      const double zi = Number(path, t, "damping rayleigh ZETA_I");
      const int j = static_cast<int>(Number(path, t, "damping rayleigh MODE_J"));
      const double zj = Number(path, t, "damping rayleigh ZETA_J");
      out.C = RayleighDampingMatrix(out.M, out.K, i, zi, j, zj);
    } else {
      throw Error("damping", fmt::format("\"{}\": \"damping modal ZETA\" or \"damping rayleigh MODE_I ZETA_I MODE_J "
                                         "ZETA_J\" (of the initial stiffness)",
                                         how));
    }
  } catch (const Error& e) {
    throw Error(where, fmt::format("{}: {}", e.where(), e.problem()));
  }
  if (t->next != t->words.size()) throw Error(Where(path, *t), "unexpected text after the damping line");
  return out;
}

}  // namespace

StructureMatrices LoadStructureFile(const std::string& path) {
  Tokens t = Tokenize(path);
  Expect(path, &t, "n", "");
  const double nd = Number(path, &t, "n");
  if (nd < 1 || nd > 10000 || nd != std::floor(nd)) {
    throw Error(Where(path, t), fmt::format("n = {} is out of range [1, 10000] (whole number)", nd));
  }
  const int n = static_cast<int>(nd);
  if (t.next < t.words.size() && t.words[t.next] == "floors") return ShearBuildingFile(path, &t, n);
  StructureMatrices m;
  Expect(path, &t, "M", "kg");
  m.M = Matrix(path, &t, n, "M") * kKgToProject;
  Expect(path, &t, "K", "kN/mm");
  m.K = Matrix(path, &t, n, "K");
  Expect(path, &t, "C", "kN*s/mm");
  m.C = Matrix(path, &t, n, "C");
  if (t.next < t.words.size() && t.words[t.next] == "iota") {
    ++t.next;
    m.iota.resize(n);
    for (int i = 0; i < n; ++i) m.iota(i) = Number(path, &t, "iota");
  }
  if (t.next != t.words.size()) {
    throw Error(Where(path, t), m.iota.size() ? "unexpected text after iota"
                                              : "unexpected text after the C matrix (only an \"iota\" line may follow)");
  }
  CheckSymmetric(path, m.M, "M");
  CheckSymmetric(path, m.K, "K");
  CheckSymmetric(path, m.C, "C");
  if (Eigen::LLT<Eigen::MatrixXd>(m.M).info() != Eigen::Success) {
    throw Error(path, "M is not positive definite");
  }
  return m;
}

void WriteStructureFile(const std::string& path, const StructureMatrices& m, const std::string& comment) {
  std::ofstream out(path);
  if (!out) throw Error(path, "cannot write the structure file");
  out << "# rths structure v1\n";
  std::istringstream c(comment);
  for (std::string line; std::getline(c, line);) out << "# " << line << "\n";
  const int n = static_cast<int>(m.M.rows());
  out << "n " << n << "\n";
  auto write = [&](const char* head, const Eigen::MatrixXd& a, double scale) {
    out << head << "\n";
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) out << fmt::format("{}{:.17g}", j ? " " : "", a(i, j) * scale);
      out << "\n";
    }
  };
  write("M kg", m.M, 1.0 / kKgToProject);
  write("K kN/mm", m.K, 1.0);
  write("C kN*s/mm", m.C, 1.0);
  if (m.iota.size() == n && (m.iota.array() != 1.0).any()) {
    out << "iota\n";
    for (int i = 0; i < n; ++i) out << fmt::format("{}{:.17g}", i ? " " : "", m.iota(i));
    out << "\n";
  }
  if (!out.flush()) throw Error(path, "cannot write the structure file");
}

bool StructureMatrices::operator==(const StructureMatrices& o) const {
  const auto same = [](const auto& a, const auto& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && (a.size() == 0 || a == b);
  };
  return same(M, o.M) && same(K, o.K) && same(C, o.C) && same(iota, o.iota);
}

Eigen::VectorXd StructureMatrices::IotaOrOnes() const {
  return iota.size() ? iota : Eigen::VectorXd::Ones(M.rows());
}

Eigen::MatrixXd ModalDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double zeta) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  const Eigen::MatrixXd& phi = eig.eigenvectors();  // mass-normalised: phi^T M phi = I
  const Eigen::VectorXd w = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  Eigen::MatrixXd C = M * phi * (2.0 * zeta * w).asDiagonal() * phi.transpose() * M;
  return 0.5 * (C + C.transpose());
}

StructureMatrices ShearBuilding(const std::vector<double>& floor_masses_kg,
                                const std::vector<double>& story_stiffness_kN_per_mm, double zeta) {
  const int n = static_cast<int>(floor_masses_kg.size());
  if (n == 0 || story_stiffness_kN_per_mm.size() != floor_masses_kg.size()) {
    throw Error("ShearBuilding", "one story stiffness per floor mass is needed");
  }
  StructureMatrices m;
  m.M = MassMatrix(floor_masses_kg);
  m.K = StoryStiffnessMatrix(story_stiffness_kN_per_mm);
  m.C = ModalDampingMatrix(m.M, m.K, zeta);
  return m;
}

Modes ModalAnalysis(const StructureMatrices& m) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(m.K, m.M);
  Modes out;
  for (int i = 0; i < eig.eigenvalues().size(); ++i) {
    const double w = std::sqrt(std::max(0.0, eig.eigenvalues()[i]));
    const Eigen::VectorXd phi = eig.eigenvectors().col(i);
    out.frequency_hz.push_back(w / (2.0 * std::numbers::pi));
    out.damping_ratio.push_back(w > 0 ? phi.dot(m.C * phi) / (2.0 * w) : 0.0);
  }
  return out;
}

LinearStructure StructureFromScenario(const models::StructureConfig& st) {
  if (st.kind != StructureKind::kFile) {
    return LinearStructure::Sdof(st.mass_kg, st.frequency_hz, st.damping_ratio, st.specimen_count);
  }
  const StructureMatrices& m = st.matrices;
  if (m.M.rows() == 0) {
    throw Error("structure.file", fmt::format("{}: not read (scenario::LoadScenario reads it)", st.file));
  }
  if (st.actuator_dof > m.M.rows()) {
    throw Error("structure.actuator_dof", fmt::format("{} is out of range [1, {}] ({} has {} DOFs)", st.actuator_dof,
                                                      m.M.rows(), st.file, m.M.rows()));
  }
  LinearStructure s = LinearStructure::Make(m.M, m.C, m.K, st.actuator_dof - 1, st.specimen_count);
  if (m.iota.size()) s.iota = m.iota;  // the file's ground influence (default ones, from Make)
  return s;
}

NonlinearBuilding NonlinearFromScenario(const StructureConfig& st) {
  if (st.kind == StructureKind::kSdof) {
    const LinearStructure lin = LinearStructure::Sdof(st.mass_kg, st.frequency_hz, st.damping_ratio, st.specimen_count);
    SpringParams spring = st.spring;
    spring.k_kN_per_mm = lin.K(0, 0);  // m w^2, the initial stiffness
    return NonlinearBuilding::Make({st.mass_kg}, {spring}, lin.C, 0, st.specimen_count);
  }
  const StructureMatrices& m = st.matrices;
  if (m.springs.empty())
    throw Error("structure.file", fmt::format("{}: a matrix file has no story springs; cr, alpha_os, newmark_implicit "
                                              "and sub-steps need a shear-building file (floors, story lines)",
                                              st.file));
  std::vector<double> masses(static_cast<std::size_t>(m.M.rows()));
  for (std::size_t i = 0; i < masses.size(); ++i) masses[i] = m.M(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) / kKgToProject;
  return NonlinearBuilding::Make(masses, m.springs, m.C, st.actuator_dof - 1, st.specimen_count);
}

StructureIntegrator SteppedIntegratorFromScenario(const StructureConfig& st, double dt_s) {
  return StructureIntegrator::Make(NonlinearFromScenario(st), dt_s, st.integrator);
}

}  // namespace rths::models
