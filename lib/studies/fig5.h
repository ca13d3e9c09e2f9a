#pragma once
/// @file Fig. 5 (docs/experiments.md E6): the 200-kN MR damper model (Eqs. 32-39, Table 3) under a
/// prescribed 25.4 mm, 1 Hz sine at six constant currents. No lockstep run: the damper alone.
#include <vector>

#include "studies/study.h"

namespace rths::studies {

struct Fig5Result {
  std::vector<double> current_A;        ///< 0, 0.5, ..., 2.5
  std::vector<double> paper_peak_kN;    ///< the reference of docs/experiments.md E6
  std::vector<double> ours_peak_kN;     ///< max |F| over the 2nd and 3rd cycles
  std::vector<Claim> claims;            ///< E6: the six peaks within 2 % of the reference
};
/// The E6 reference peaks [kN] at 0, 0.5, 1.0, 1.5, 2.0, 2.5 A.
const std::vector<double>& Fig5ReferencePeaksKn();
/// Writes fig5_peaks.csv (current_A,paper_peak_kN,ours_peak_kN), fig5_loops.csv (t, x, v, F per
/// current) and fig5.png (force-time, force-displacement, force-velocity side by side).
Fig5Result ReproduceFig5(const ReproduceOptions& opts);

}  // namespace rths::studies
