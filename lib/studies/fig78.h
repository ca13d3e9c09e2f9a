#pragma once
/// @file Figs. 7 and 8 (docs/experiments.md E2): G_yr through each controller of Table 1 at 0.0 A
/// (Fig. 7) and 2.5 A (Fig. 8), and E2's statements measured on the curves.
#include <string>
#include <vector>

#include "studies/frequency.h"
#include "studies/study.h"
#include "studies/table2.h"

namespace rths::studies {

struct Fig78Result {
  std::string condition;            ///< "0.0A" (Fig. 7) or "2.5A" (Fig. 8)
  std::vector<BodeCurve> curves;    ///< G_yr per controller, in Table 1's order
  std::vector<Claim> claims;        ///< E2's statements, measured on the curves (was `checks`)
};
/// The Table 2 controllers of one condition, in order ("0.0A" or "2.5A").
std::vector<Table2Controller> ControllersOf(const std::string& condition);
/// E2: the same BLWN as the desired displacement through each controller of the condition
/// (figure "fig7": 0.0 A, "fig8": 2.5 A); G_yr by H1. Writes <figure>.png (magnitude, phase and
/// time lag, 0-50 Hz, one curve per controller), <figure>.csv
/// (controller,f_hz,magnitude,phase_deg,time_lag_ms,coherence), <figure>.md and runs/.
Fig78Result ReproduceFig78(const ReproduceOptions& opts, const std::string& figure);

}  // namespace rths::studies
