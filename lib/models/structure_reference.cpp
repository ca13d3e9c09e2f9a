#include "models/structure_reference.h"

#include <cmath>

#include <cvode/cvode.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <Eigen/Dense>

#include "core/error.h"
#include "models/structure_integrator.h"

namespace rths::models {
namespace {

struct Problem {
  const NonlinearBuilding* b;
  double dt;
  const std::vector<double>* ag;
  const std::vector<double>* f;
  std::vector<int> bw_slot;  // per story: index of its z in the state, or -1
  Eigen::MatrixXd m_inv;
  Eigen::VectorXd m_iota, v, force, rhs;
};

// Linear interpolation of samples at k dt (held past the last).
double At(const std::vector<double>& s, double t, double dt) {
  if (s.empty()) return 0.0;
  const double q = t / dt;
  const auto k = static_cast<std::size_t>(std::max(0.0, std::floor(q)));
  if (k + 1 >= s.size()) return s.back();
  const double w = q - static_cast<double>(k);
  return s[k] + (s[k + 1] - s[k]) * w;
}

int Rhs(double t, N_Vector y, N_Vector ydot, void* ctx) {
  Problem& p = *static_cast<Problem*>(ctx);
  const NonlinearBuilding& b = *p.b;
  const int n = b.dofs();
  const double* Y = N_VGetArrayPointer(y);
  double* D = N_VGetArrayPointer(ydot);
  for (int i = 0; i < n; ++i) p.v(i) = Y[n + i];
  for (int i = 0; i < n; ++i) {  // story forces
    const SpringParams& s = b.springs[i];
    const double u = Y[i] - (i > 0 ? Y[i - 1] : 0.0);
    const double du = Y[n + i] - (i > 0 ? Y[n + i - 1] : 0.0);
    const int z = p.bw_slot[i];
    if (z < 0) {
      p.force(i) = s.k_kN_per_mm * u;
      continue;
    }
    const double zi = Y[z], ei = Y[z + 1];
    const double dz = du * BoucWenSlope(s, zi, ei, du >= 0.0 ? 1.0 : -1.0);
    D[z] = dz;
    D[z + 1] = (1.0 - s.alpha) * s.k_kN_per_mm * zi * (du - dz);
    p.force(i) = s.alpha * s.k_kN_per_mm * u + (1.0 - s.alpha) * s.k_kN_per_mm * zi;
  }
  for (int i = 0; i < n; ++i)
    p.rhs(i) = -(p.force(i) - (i + 1 < n ? p.force(i + 1) : 0.0));
  p.rhs -= At(*p.ag, t, p.dt) * p.m_iota + At(*p.f, t, p.dt) * b.specimen_dir;
  p.rhs.noalias() -= b.C * p.v;
  for (int i = 0; i < n; ++i) D[i] = Y[n + i];
  const Eigen::VectorXd acc = p.m_inv * p.rhs;
  for (int i = 0; i < n; ++i) D[n + i] = acc(i);
  return 0;
}

ReferenceSolution BilinearReference(const NonlinearBuilding& b, double dt,
                                    const std::vector<double>& ag, const std::vector<double>& f) {
  const int r = kBilinearReferenceRefinement;
  const double h = dt / r;
  const std::size_t N = ag.size();
  IntegratorConfig c;
  c.kind = IntegratorKind::kNewmarkImplicit;
  c.newton_iterations = 10;
  const StructureIntegrator integ = StructureIntegrator::Make(b, h, c);
  IntegratorState s = MakeIntegratorState(b);
  ReferenceSolution out;
  out.method = fmt::format("newmark_implicit_dt/{}", r);
  out.x_mm.resize(b.dofs(), static_cast<Eigen::Index>(N));
  for (std::size_t k = 0; k < N; ++k) {
    out.x_mm.col(static_cast<Eigen::Index>(k)) = s.x;
    if (k + 1 == N) break;
    for (int j = 0; j < r; ++j) {
      const double t0 = (k + static_cast<double>(j) / r) * dt, t1 = t0 + h;
      Advance(integ, &s, At(ag, t0, dt), At(ag, t1, dt), At(f, t0, dt));
    }
  }
  for (const SpringState& st : s.building.committed) out.story_energy_kN_mm.push_back(st.energy_kN_mm);
  out.hysteretic_energy_kN_mm = s.building.HystereticEnergy();
  return out;
}

void Check(bool ok, const char* what) {
  if (!ok) throw Error("SolveReference", fmt::format("{} failed", what));
}

}  // namespace

ReferenceSolution SolveReference(const NonlinearBuilding& b, double dt, const std::vector<double>& ag,
                                 const std::vector<double>& f, double rtol) {
  const int n = b.dofs();
  const std::size_t N = ag.size();
  if (!f.empty() && f.size() != N)
    throw Error("SolveReference", fmt::format("force history has {} samples, ground {}", f.size(), N));
  if (!(dt > 0.0) || N == 0 || !(rtol > 0.0))
    throw Error("SolveReference", "dt_s and rtol must be > 0 and the record not empty");
  for (const SpringParams& s : b.springs)
    if (s.kind == SpringKind::kBilinear) return BilinearReference(b, dt, ag, f);

  Problem p{&b, dt, &ag, &f, std::vector<int>(n, -1), b.M.inverse(), b.M * b.iota,
            Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n)};
  int size = 2 * n;
  for (int i = 0; i < n; ++i)
    if (b.springs[i].kind == SpringKind::kBoucWen) p.bw_slot[i] = size, size += 2;

  SUNContext ctx = nullptr;
  Check(SUNContext_Create(nullptr, &ctx) == 0, "SUNContext_Create");
  N_Vector y = N_VNew_Serial(size, ctx), atol = N_VNew_Serial(size, ctx);
  SUNMatrix J = SUNDenseMatrix(size, size, ctx);
  SUNLinearSolver ls = SUNLinSol_Dense(y, J, ctx);
  void* cv = CVodeCreate(CV_BDF, ctx);
  const auto free_all = [&] {
    CVodeFree(&cv);
    SUNLinSolFree(ls);
    SUNMatDestroy(J);
    N_VDestroy(atol);
    N_VDestroy(y);
    SUNContext_Free(&ctx);
  };
  ReferenceSolution out;
  out.method = "cvode_bdf";
  out.x_mm.resize(n, static_cast<Eigen::Index>(N));
  try {
    N_VConst(0.0, y);
    double* a = N_VGetArrayPointer(atol);
    for (int i = 0; i < size; ++i) a[i] = i < n ? 1e-9 : (i < 2 * n ? 1e-7 : 1e-9);  // mm, mm/s, mm | kN mm
    Check(cv != nullptr && ls != nullptr, "CVodeCreate");
    Check(CVodeInit(cv, Rhs, 0.0, y) == CV_SUCCESS, "CVodeInit");
    Check(CVodeSVtolerances(cv, rtol, atol) == CV_SUCCESS, "CVodeSVtolerances");
    Check(CVodeSetUserData(cv, &p) == CV_SUCCESS, "CVodeSetUserData");
    Check(CVodeSetMaxNumSteps(cv, 100000) == CV_SUCCESS, "CVodeSetMaxNumSteps");
    Check(CVodeSetLinearSolver(cv, ls, J) == CV_SUCCESS, "CVodeSetLinearSolver");
    const double* Y = N_VGetArrayPointer(y);
    for (std::size_t k = 0; k < N; ++k) {
      if (k > 0) {
        const double tout = static_cast<double>(k) * dt;
        double t = 0.0;
        Check(CVodeSetStopTime(cv, tout) == CV_SUCCESS, "CVodeSetStopTime");
        const int flag = CVode(cv, tout, y, &t, CV_NORMAL);
        if (flag < 0)
          throw Error("SolveReference", fmt::format("CVODE failed at t = {} s (flag {})", t, flag));
      }
      for (int i = 0; i < n; ++i) out.x_mm(i, static_cast<Eigen::Index>(k)) = Y[i];
    }
    for (int i = 0; i < n; ++i) {
      const double e = p.bw_slot[i] >= 0 ? Y[p.bw_slot[i] + 1] : 0.0;
      out.story_energy_kN_mm.push_back(e);
      out.hysteretic_energy_kN_mm += e;
    }
    CVodeGetNumSteps(cv, &out.internal_steps);
  } catch (...) {
    free_all();
    throw;
  }
  free_all();
  return out;
}

ResponseSummary Summarize(const Eigen::MatrixXd& x) {
  const Eigen::Index n = x.rows(), N = x.cols();
  ResponseSummary s;
  s.peak_drift_mm.assign(n, 0.0);
  s.residual_drift_mm.assign(n, 0.0);
  for (Eigen::Index k = 0; k < N; ++k)
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d = x(i, k) - (i > 0 ? x(i - 1, k) : 0.0);
      s.peak_drift_mm[i] = std::max(s.peak_drift_mm[i], std::abs(d));
      if (k + 1 == N) s.residual_drift_mm[i] = d;
    }
  if (n > 0 && N > 0) {
    s.peak_roof_mm = x.row(n - 1).cwiseAbs().maxCoeff();
    s.residual_roof_mm = x(n - 1, N - 1);
  }
  return s;
}

double NrmsePct(const Eigen::Ref<const Eigen::RowVectorXd>& x, const Eigen::Ref<const Eigen::RowVectorXd>& ref) {
  if (x.size() != ref.size())
    throw Error("NrmsePct", fmt::format("sizes differ ({} vs {})", x.size(), ref.size()));
  // Eq. 31 by Eigen's (vectorised) sums, not signal::RmsErrorPercent's sample-by-sample ones: the
  // two can differ in the last bit, and the structure tables print these numbers.
  const double den = ref.squaredNorm();
  return den > 0.0 ? 100.0 * std::sqrt((x - ref).squaredNorm() / den) : 0.0;
}

}  // namespace rths::models
