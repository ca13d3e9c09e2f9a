#pragma once
/// @file The reference structure's records of one sample as S5_Evaluation.m takes them (docs/marths.md
/// "Criteria"), from its Newmark state: the one piece the in-process loop (studies/marths_loop.h)
/// and the lockstep run's score (participants/marths_run.h) both append with.
#include "models/marths_structure.h"
#include "models/newmark_linear.h"
#include "signal/marths_criteria.h"

namespace rths::models::marths {

/// Appends x_ref = 1000 U_27 [mm], r_ref = -U_21 [rad] and the stories' x2_ref, r2_ref, x3_ref,
/// r3_ref (U_26, U_22, U_13, U_3 [m, rad]) of `ref` to `g`.
inline void AppendReference(const NewmarkLinearState& ref, signal::MarthsSignals* g) {
  g->x_ref.push_back(1000.0 * ref.U(Index(kDofX)));
  g->r_ref.push_back(-ref.U(Index(kDofTheta)));
  g->x2_ref.push_back(ref.U(Index(kDofX2)));
  g->r2_ref.push_back(ref.U(Index(kDofTheta2nd)));
  g->x3_ref.push_back(ref.U(Index(kDofX3)));
  g->r3_ref.push_back(ref.U(Index(kDofTheta3rd)));
}

}  // namespace rths::models::marths
