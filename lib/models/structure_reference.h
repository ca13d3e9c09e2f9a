#pragma once
/// @file A reference solution of a NonlinearBuilding under a ground record, and the response
/// measures the integrators are compared by (docs/structures.md, "Measured accuracy").
///
/// The continuous model: states x, v (n each) and, per Bouc-Wen story, z and E_h:
///     x' = v,  M v' = -M iota a_g(t) - s f(t) - C v - R(x, z),
///     z_i' = u_i' dz/du(z_i, E_i, sgn u_i'),  E_i' = (1 - alpha_i) k_i z_i (u_i' - z_i')
/// (story_spring.h), a_g(t) and f(t) linear between the samples at t_k = k dt. Integrated by CVODE
/// (SUNDIALS: variable-order BDF, Newton on a dense difference-quotient Jacobian, adaptive step) at
/// rtol = 1e-10, with a stop at every sample so that no step straddles a kink of the inputs; the
/// output at t_k is CVODE's own step end there.
/// A bilinear story has no smooth rate form (its yield switch is a discontinuous tangent, which an
/// ODE solver steps over at first order); a building with one is instead integrated by
/// newmark_implicit at dt / kBilinearReferenceRefinement with 10 Newton iterations per step (its
/// return mapping is exact), the inputs interpolated linearly, sampled at t_k.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "models/nonlinear_building.h"

namespace rths::models {

inline constexpr int kBilinearReferenceRefinement = 64;

struct ReferenceSolution {
  Eigen::MatrixXd x_mm;                          ///< n x N: x(t_k) [mm]
  std::vector<double> story_energy_kN_mm;        ///< E_h of each story at t_{N-1} [kN mm]
  double hysteretic_energy_kN_mm = 0.0;          ///< their sum
  std::string method;                            ///< "cvode_bdf" | "newmark_implicit_dt/64"
  long internal_steps = 0;                       ///< CVODE's steps (diagnostics)
};

/// Solves from rest over N = ground_mm_s2.size() samples of step dt_s [s]; force_kN: f at each
/// sample [kN] or empty for none. rtol > 0 (CVODE). Throws rths::Error on a solver failure or a
/// force history of another length.
ReferenceSolution SolveReference(const NonlinearBuilding& b, double dt_s,
                                 const std::vector<double>& ground_mm_s2,
                                 const std::vector<double>& force_kN = {}, double rtol = 1e-10);

/// Peak and residual story drifts and roof displacement of a displacement history.
struct ResponseSummary {
  std::vector<double> peak_drift_mm;      ///< max_k |x_i - x_{i-1}| per story [mm]
  std::vector<double> residual_drift_mm;  ///< x_i - x_{i-1} at the last sample [mm]
  double peak_roof_mm = 0.0;              ///< max_k |x_n| [mm]
  double residual_roof_mm = 0.0;          ///< x_n at the last sample [mm]
};
/// Of x_mm (n x N, column k = sample k).
ResponseSummary Summarize(const Eigen::MatrixXd& x_mm);

/// 100 sqrt(sum_k (x_k - ref_k)^2 / sum_k ref_k^2) [%] (the paper's Eq. 31 form; diagnosis::Nrmse
/// is the same measure, in a library models may not link). Sizes must agree.
double NrmsePct(const Eigen::Ref<const Eigen::RowVectorXd>& x, const Eigen::Ref<const Eigen::RowVectorXd>& ref);

}  // namespace rths::models
