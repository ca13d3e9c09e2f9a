#pragma once
/// @file A small SUNDIALS wrapper shared by the nonlinear models: integrates x' = f(t, x) over one
/// step [t0, t1] (docs/models.md, "Integrating a step").
///
/// Two methods (OdeMethod):
///  - kErk (default): ARKODE's explicit Runge-Kutta stepper (ERKStep) with the Dormand-Prince
///    5(4) pair, embedded error control at (rtol, atol), and the whole step t1 - t0 as its first
///    trial step. The models' states are not stiff at the lockstep step (0.5 ms): the Bouc-Wen
///    and servo eigenvalues give |h lambda| below 1.5, inside DP5's stability region, and a
///    one-step method restarts for free, whereas BDF restarts at order 1 on every step. For the
///    MR damper it is about ten times cheaper than kBdf at the same rtol, and more accurate
///    (tests/models/damper_accuracy_test.cpp, bench/memq.cpp).
///  - kBdf: CVODE's variable-order BDF with Newton iterations on a dense Jacobian, for stiff
///    systems. The Jacobian comes from difference quotients computed here, with CVODE's own
///    increments (cvLsDenseDQJac) but into preallocated storage: CVODE's built-in version
///    allocates a vector header per evaluation.
///
/// Inputs are piecewise constant per step, so every Advance() re-initialises the integrator at t0
/// (ERKStepReInit / CVodeReInit, which also clear the step-size and error histories): the result
/// depends only on (t0, t1, x), never on earlier calls, and re-answering a step from a committed
/// state reproduces it bit for bit.
#include <span>
#include <string>

// SUNDIALS handle types (sundials_nvector.h, sundials_matrix.h, ...), kept out of this header.
struct _generic_N_Vector;
struct _generic_SUNMatrix;
struct _generic_SUNLinearSolver;
struct _SUNContext;

namespace rths::models {

/// Right-hand side x' = f(t, x) with x and xdot of the stepper's size. Returns 0 on success,
/// > 0 for a recoverable error (kBdf retries with a smaller step; kErk stops), < 0 to stop. It is
/// called from C code: it must not throw, and it must allocate nothing for Advance() not to.
using OdeRhs = int (*)(double t, const double* x, double* xdot, void* ctx);

/// How OdeStepper integrates a step (the @file says when to use which).
enum class OdeMethod {
  kErk,  ///< ARKODE ERKStep, Dormand-Prince 5(4), first trial step t1 - t0 (default)
  kBdf,  ///< CVODE BDF (orders 1-5), Newton on a dense difference-quotient Jacobian
};

class OdeStepper {
 public:
  /// Allocates every SUNDIALS object once. n > 0 states; rtol relative tolerance (> 0); atol the
  /// absolute tolerance per state (size n, > 0, in each state's unit). ctx is passed to rhs and
  /// must outlive the stepper. Throws rths::Error.
  OdeStepper(int n, double rtol, std::span<const double> atol, OdeRhs rhs, void* ctx,
             OdeMethod method = OdeMethod::kErk);
  /// Same absolute tolerance for every state.
  OdeStepper(int n, double rtol, double atol, OdeRhs rhs, void* ctx,
             OdeMethod method = OdeMethod::kErk);
  ~OdeStepper();
  OdeStepper(const OdeStepper&) = delete;
  OdeStepper& operator=(const OdeStepper&) = delete;

  /// Integrates from x(t0) = x_inout to t1 > t0 (never past t1: stop time) and writes x(t1) to
  /// x_inout (size n). Allocates nothing. Throws rths::Error with the integrator's flag on failure.
  void Advance(double t0, double t1, double* x_inout);

  int size() const { return n_; }
  OdeMethod method() const { return method_; }
  /// Internal steps taken by the last Advance() (diagnostics).
  long last_steps() const;
  /// Right-hand side evaluations of the last Advance(), Jacobian columns included (diagnostics).
  long last_rhs_evals() const;

 private:
  static int Rhs(double t, _generic_N_Vector* x, _generic_N_Vector* xdot, void* self);
  static int ErkRhs(double t, _generic_N_Vector* x, _generic_N_Vector* xdot, void* self);
  static int Jac(double t, _generic_N_Vector* x, _generic_N_Vector* fx, _generic_SUNMatrix* jac,
                 void* self, _generic_N_Vector* tmp1, _generic_N_Vector* tmp2,
                 _generic_N_Vector* tmp3);
  static void ErrHandler(int code, const char* module, const char* function, char* msg, void* self);
  void Init(double rtol, std::span<const double> atol);
  void InitErk(double rtol);
  /// One Advance() over [0, 1] of x' = 0 from x = 0: whatever the integrator sets up lazily on
  /// its first step (CVODE's saved Jacobian, ARKODE's workspaces) is set up at construction, so
  /// that Advance() never allocates.
  void WarmUp();
  void Free();

  int n_;
  OdeMethod method_;
  OdeRhs rhs_;
  void* ctx_;
  _SUNContext* sunctx_ = nullptr;
  _generic_N_Vector* x_ = nullptr;
  _generic_N_Vector* atol_ = nullptr;
  _generic_N_Vector* ewt_ = nullptr;  // error weights, for the Jacobian increments
  _generic_SUNMatrix* jac_ = nullptr;
  _generic_SUNLinearSolver* ls_ = nullptr;
  void* cvode_ = nullptr;
  void* arkode_ = nullptr;
  long jac_rhs_evals_ = 0;  // kBdf: rhs calls of the Jacobian in the last Advance()
  std::string last_message_;  // CVODE's last error text (written only on failure)
};

}  // namespace rths::models
