#pragma once
/// @file Fig. 6 (docs/experiments.md E1): identification of G_yu at 0.0 A and 2.5 A, 3-pole fits
/// against Eqs. 28-30.
#include <string>
#include <vector>

#include "ident/fit.h"
#include "models/servo_linear.h"
#include "studies/frequency.h"
#include "studies/study.h"

namespace rths::studies {

struct Fig6Model {
  std::string condition;            ///< "0.0A", "2.5A", "avg" (the fit of the averaged response)
  models::ServoModel3 paper;      ///< Eq. 28, 29, 30
  ident::FitSummary fit;            ///< our 3-pole fit (ZOH-aware)
  double max_diff_pct = 0.0;        ///< largest |ours / paper - 1| over K, p, b, c [%]
};
struct Fig6Result {
  std::vector<BodeCurve> measured;  ///< H1 of G_yu at 0.0 A and 2.5 A
  std::vector<Fig6Model> models;    ///< 0.0A, 2.5A, avg
  double tolerance_pct = 0.0;       ///< E1: 3 % on the linear plant, 8 % on the physical one
  std::vector<Claim> claims;        ///< E1 on the 0.0 A and 2.5 A fits (one claim; was `verdict`)
};
/// E1: BLWN 0-50 Hz, RMS 0.254 mm commanded with no controller at 0.0 A and 2.5 A (60 s;
/// --quick 16 s); H1 with coherence; 3-pole fits over 0.5-40 Hz. Writes fig6.png (magnitude,
/// phase, time lag with the fitted models overlaid), fig6.csv (the measured curves),
/// fig6_models.csv (condition,parameter,paper,ours,diff_pct), fig6.md and runs/.
Fig6Result ReproduceFig6(const ReproduceOptions& opts);

}  // namespace rths::studies
