#include "models/ode.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "core/error.h"

namespace rths::models {
namespace {

constexpr long kMaxStepsPerAdvance = 100000;

// Throws for a failed SUNDIALS call (construction only) or a null handle.
void Check(bool ok, const char* call) {
  if (!ok) throw Error("OdeStepper", fmt::format("{} failed", call));
}

}  // namespace

OdeStepper::OdeStepper(int n, double rtol, std::span<const double> atol, OdeRhs rhs, void* ctx,
                       OdeMethod method)
    : n_(n), method_(method), rhs_(rhs), ctx_(ctx) {
  if (n <= 0) throw Error("OdeStepper", fmt::format("state size must be > 0 (got {})", n));
  if (!(rtol > 0.0) || !std::isfinite(rtol))
    throw Error("OdeStepper", fmt::format("rtol must be finite and > 0 (got {})", rtol));
  if (static_cast<int>(atol.size()) != n)
    throw Error("OdeStepper", fmt::format("atol has {} entries, expected {}", atol.size(), n));
  for (double a : atol)
    if (!(a > 0.0) || !std::isfinite(a))
      throw Error("OdeStepper", fmt::format("atol must be finite and > 0 (got {})", a));
  if (rhs == nullptr) throw Error("OdeStepper", "rhs is null");
  try {
    Init(rtol, atol);
  } catch (...) {
    Free();
    throw;
  }
}

OdeStepper::OdeStepper(int n, double rtol, double atol, OdeRhs rhs, void* ctx, OdeMethod method)
    : OdeStepper(n, rtol, std::span<const double>(std::vector<double>(n > 0 ? n : 0, atol)), rhs,
                 ctx, method) {}

void OdeStepper::Init(double rtol, std::span<const double> atol) {
  Check(SUNContext_Create(nullptr, &sunctx_) == 0, "SUNContext_Create");
  x_ = N_VNew_Serial(n_, sunctx_);
  atol_ = N_VNew_Serial(n_, sunctx_);
  ewt_ = N_VNew_Serial(n_, sunctx_);
  Check(x_ != nullptr && atol_ != nullptr && ewt_ != nullptr, "N_VNew_Serial");
  N_VConst(0.0, x_);
  double* a = N_VGetArrayPointer(atol_);
  for (int i = 0; i < n_; ++i) a[i] = atol[i];
  if (method_ == OdeMethod::kErk) {
    InitErk(rtol);
    return;
  }

  cvode_ = CVodeCreate(CV_BDF, sunctx_);
  Check(cvode_ != nullptr, "CVodeCreate");
  Check(CVodeSetErrHandlerFn(cvode_, &OdeStepper::ErrHandler, this) == CV_SUCCESS,
        "CVodeSetErrHandlerFn");
  Check(CVodeInit(cvode_, &OdeStepper::Rhs, 0.0, x_) == CV_SUCCESS, "CVodeInit");
  Check(CVodeSVtolerances(cvode_, rtol, atol_) == CV_SUCCESS, "CVodeSVtolerances");
  Check(CVodeSetUserData(cvode_, this) == CV_SUCCESS, "CVodeSetUserData");
  Check(CVodeSetMaxNumSteps(cvode_, kMaxStepsPerAdvance) == CV_SUCCESS, "CVodeSetMaxNumSteps");
  jac_ = SUNDenseMatrix(n_, n_, sunctx_);
  Check(jac_ != nullptr, "SUNDenseMatrix");
  ls_ = SUNLinSol_Dense(x_, jac_, sunctx_);
  Check(ls_ != nullptr, "SUNLinSol_Dense");
  Check(CVodeSetLinearSolver(cvode_, ls_, jac_) == CV_SUCCESS, "CVodeSetLinearSolver");
  Check(CVodeSetJacFn(cvode_, &OdeStepper::Jac) == CV_SUCCESS, "CVodeSetJacFn");

  // CVODE allocates its saved Jacobian lazily, on the first step: take one step of x' = 0 now
  // so that Advance() never allocates.
  WarmUp();
}

void OdeStepper::WarmUp() {
  const OdeRhs user_rhs = rhs_;
  rhs_ = [](double, const double*, double* xdot, void* ctx) {
    for (int i = 0, n = *static_cast<const int*>(ctx); i < n; ++i) xdot[i] = 0.0;
    return 0;
  };
  void* user_ctx = ctx_;
  ctx_ = &n_;
  std::vector<double> x0(n_, 0.0);
  Advance(0.0, 1.0, x0.data());
  rhs_ = user_rhs, ctx_ = user_ctx;
}

void OdeStepper::InitErk(double rtol) {
  arkode_ = ERKStepCreate(&OdeStepper::ErkRhs, 0.0, x_, sunctx_);
  Check(arkode_ != nullptr, "ERKStepCreate");
  Check(ERKStepSetErrHandlerFn(arkode_, &OdeStepper::ErrHandler, this) == ARK_SUCCESS,
        "ERKStepSetErrHandlerFn");
  Check(ERKStepSVtolerances(arkode_, rtol, atol_) == ARK_SUCCESS, "ERKStepSVtolerances");
  Check(ERKStepSetUserData(arkode_, this) == ARK_SUCCESS, "ERKStepSetUserData");
  Check(ERKStepSetTableNum(arkode_, ARKODE_DORMAND_PRINCE_7_4_5) == ARK_SUCCESS,
        "ERKStepSetTableNum");
  Check(ERKStepSetMaxNumSteps(arkode_, kMaxStepsPerAdvance) == ARK_SUCCESS,
        "ERKStepSetMaxNumSteps");
  // One warm-up step of x' = 0, as for CVODE: whatever ARKODE sets up lazily is set up here.
  WarmUp();
}

OdeStepper::~OdeStepper() { Free(); }

void OdeStepper::Free() {
  if (cvode_) CVodeFree(&cvode_);
  if (arkode_) ERKStepFree(&arkode_);
  if (ls_) SUNLinSolFree(ls_);
  if (jac_) SUNMatDestroy(jac_);
  if (ewt_) N_VDestroy(ewt_);
  if (atol_) N_VDestroy(atol_);
  if (x_) N_VDestroy(x_);
  if (sunctx_) SUNContext_Free(&sunctx_);
  cvode_ = nullptr, arkode_ = nullptr, ls_ = nullptr, jac_ = nullptr, ewt_ = nullptr, atol_ = nullptr, x_ = nullptr;
}

int OdeStepper::ErkRhs(double t, N_Vector x, N_Vector xdot, void* self) {
  // ARKODE takes any nonzero return as a failure (no recoverable retry in ERKStep).
  auto* me = static_cast<OdeStepper*>(self);
  return me->rhs_(t, N_VGetArrayPointer(x), N_VGetArrayPointer(xdot), me->ctx_);
}

int OdeStepper::Rhs(double t, N_Vector x, N_Vector xdot, void* self) {
  auto* me = static_cast<OdeStepper*>(self);
  return me->rhs_(t, N_VGetArrayPointer(x), N_VGetArrayPointer(xdot), me->ctx_);
}

// Dense difference-quotient Jacobian, column j: (f(x + inc e_j) - f(x)) / inc with
// inc = max(sqrt(uround) |x_j|, min_inc / ewt_j), min_inc = 1000 |h| uround n ||f||_wrms
// (as cvLsDenseDQJac). tmp1 holds f(x + inc e_j); x is restored after each column.
int OdeStepper::Jac(double t, N_Vector x, N_Vector fx, SUNMatrix jac, void* self, N_Vector tmp1,
                    N_Vector, N_Vector) {
  auto* me = static_cast<OdeStepper*>(self);
  double h = 0.0;
  if (CVodeGetErrWeights(me->cvode_, me->ewt_) != CV_SUCCESS) return -1;
  if (CVodeGetCurrentStep(me->cvode_, &h) != CV_SUCCESS) return -1;
  const double uround = SUN_UNIT_ROUNDOFF, srur = std::sqrt(uround);
  const double fnorm = N_VWrmsNorm(fx, me->ewt_);
  const double min_inc = fnorm != 0.0 ? 1000.0 * std::abs(h) * uround * me->n_ * fnorm : 1.0;
  double* xv = N_VGetArrayPointer(x);
  const double* f0 = N_VGetArrayPointer(fx);
  const double* f1 = N_VGetArrayPointer(tmp1);
  const double* ewt = N_VGetArrayPointer(me->ewt_);
  for (int j = 0; j < me->n_; ++j) {
    const double xj = xv[j];
    const double inc = std::max(srur * std::abs(xj), min_inc / ewt[j]);
    xv[j] = xj + inc;
    const int flag = me->rhs_(t, xv, N_VGetArrayPointer(tmp1), me->ctx_);
    ++me->jac_rhs_evals_;
    xv[j] = xj;
    if (flag != 0) return flag;
    double* col = SUNDenseMatrix_Column(jac, j);
    for (int i = 0; i < me->n_; ++i) col[i] = (f1[i] - f0[i]) / inc;
  }
  return 0;
}

void OdeStepper::ErrHandler(int, const char* module, const char* function, char* msg, void* self) {
  static_cast<OdeStepper*>(self)->last_message_ = fmt::format("{}/{}: {}", module, function, msg);
}

void OdeStepper::Advance(double t0, double t1, double* x_inout) {
  if (!(t1 > t0))
    throw Error("OdeStepper", fmt::format("Advance needs t1 > t0 (got {} -> {})", t0, t1));
  double* x = N_VGetArrayPointer(x_);
  for (int i = 0; i < n_; ++i) x[i] = x_inout[i];
  if (method_ == OdeMethod::kErk) {
    // ReInit (not ERKStepReset, which keeps the step-size history): a function of (t0, t1, x).
    int flag = ERKStepReInit(arkode_, &OdeStepper::ErkRhs, t0, x_);
    if (flag == ARK_SUCCESS) flag = ERKStepSetInitStep(arkode_, t1 - t0);
    if (flag == ARK_SUCCESS) flag = ERKStepSetStopTime(arkode_, t1);
    double t_reached = t0;
    if (flag == ARK_SUCCESS) flag = ERKStepEvolve(arkode_, t1, x_, &t_reached, ARK_NORMAL);
    if (flag < 0) {
      char* name = ERKStepGetReturnFlagName(flag);
      const std::string what =
          fmt::format("ARKODE ERKStep failed over [{}, {}] s with {} ({}) at t = {}: {}", t0, t1,
                      name ? name : "?", flag, t_reached, last_message_);
      std::free(name);
      throw Error("OdeStepper", what);
    }
    for (int i = 0; i < n_; ++i) x_inout[i] = x[i];
    return;
  }
  jac_rhs_evals_ = 0;
  int flag = CVodeReInit(cvode_, t0, x_);
  if (flag == CV_SUCCESS) flag = CVodeSetStopTime(cvode_, t1);
  double t_reached = t0;
  if (flag == CV_SUCCESS) flag = CVode(cvode_, t1, x_, &t_reached, CV_NORMAL);
  if (flag < 0) {
    char* name = CVodeGetReturnFlagName(flag);
    const std::string what = fmt::format("CVODE failed over [{}, {}] s with {} ({}) at t = {}: {}",
                                         t0, t1, name ? name : "?", flag, t_reached, last_message_);
    std::free(name);
    throw Error("OdeStepper", what);
  }
  for (int i = 0; i < n_; ++i) x_inout[i] = x[i];
}

long OdeStepper::last_steps() const {
  long steps = 0;
  if (arkode_) ERKStepGetNumSteps(arkode_, &steps);
  if (cvode_) CVodeGetNumSteps(cvode_, &steps);
  return steps;
}

long OdeStepper::last_rhs_evals() const {
  long evals = 0;
  if (arkode_) ERKStepGetNumRhsEvals(arkode_, &evals);
  if (cvode_) CVodeGetNumRhsEvals(cvode_, &evals), evals += jac_rhs_evals_;
  return evals;
}

}  // namespace rths::models
