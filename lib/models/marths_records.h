#pragma once
/// @file The reference structure's records of one sample as S5_Evaluation.m takes them (docs/marths.md
/// "Criteria"), from its Newmark state: the one piece the in-process loop (studies/marths_loop.h)
/// and the lockstep run's score (participants/marths_run.h) both append with.
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

}  // namespace rths::models::marths
