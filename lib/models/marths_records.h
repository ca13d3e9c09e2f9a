#pragma once
/// @file The structures' records of one sample as S5_Evaluation.m takes them (docs/marths.md
/// "Criteria"): the reference's from its Newmark state and the numerical substructure's from its
/// displacements, the pieces the in-process loop (studies/marths_loop.h) and the lockstep run's
/// score (participants/marths_run.h) both append with.
#include "models/marths_structure.h"
#include "models/newmark_linear.h"
#include "signal/marths_criteria.h"

namespace rths::models::marths {

/// Appends x_ref = 1000 U_x [mm], r_ref = -U_theta [rad] and the stories' x2_ref, r2_ref, x3_ref,
/// r3_ref (U_x2, U_theta2nd, U_x3, U_theta3rd [m, rad]; the benchmark's DOFs 27, 21, 26, 22, 13, 3)
/// of `ref` to `g`.
inline void AppendReference(const NewmarkLinearState& ref, const FrameDofs& d, signal::MarthsSignals* g) {
  g->x_ref.push_back(1000.0 * ref.U(Index(d.x())));
  g->r_ref.push_back(-ref.U(Index(d.theta())));
  g->x2_ref.push_back(ref.U(Index(d.x2())));
  g->r2_ref.push_back(ref.U(Index(d.theta_2nd())));
  g->x3_ref.push_back(ref.U(Index(d.x3())));
  g->r3_ref.push_back(ref.U(Index(d.theta_3rd())));
}

/// Appends the numerical substructure's x_num = x_mm [mm] (passed as the caller has it: the loop's
/// 1000 U_x, the log's x_mm), r_num = -u(theta) [rad] and the stories' x2_num, r2_num, x3_num,
/// r3_num = u(dof) [m, rad], where u(dof) is the displacement of a 1-based DOF in SI.
template <typename U>
void AppendNumerical(const FrameDofs& d, double x_mm, U&& u, signal::MarthsSignals* g) {
  g->x_num.push_back(x_mm);
  g->r_num.push_back(-u(d.theta()));
  g->x2_num.push_back(u(d.x2()));
  g->r2_num.push_back(u(d.theta_2nd()));
  g->x3_num.push_back(u(d.x3()));
  g->r3_num.push_back(u(d.theta_3rd()));
}

}  // namespace rths::models::marths
