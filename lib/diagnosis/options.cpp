#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "diagnosis/diagnosis.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis {

bool Options::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  // A real field within [lo, hi] (open ends where lo_open / hi_open).
  auto real = [&](const char* name, double v, double lo, double hi, bool lo_open, bool hi_open) {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (ok) return true;
    const std::string range = std::isinf(hi) ? fmt::format("{} {}", lo_open ? ">" : ">=", lo)
                                             : fmt::format("{}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
    return fail(fmt::format("{} = {}: allowed {}", name, v, range));
  };
  auto integer = [&](const char* name, int v, int lo, int hi) {
    if (v >= lo && v <= hi) return true;
    return fail(fmt::format("{} = {}: allowed [{}, {}]", name, v, lo, hi));
  };
  const double inf = std::numeric_limits<double>::infinity();
  return real("warmup_s", warmup_s, 0.0, inf, false, true) &&
         real("smooth_hz", smooth_hz, 0.0, inf, true, true) &&
         real("max_smooth_cycles_per_sample", max_smooth_cycles_per_sample, 0.0, 0.5, true, true) &&
         real("noise_band_lo", noise_band_lo, 0.0, 1.0, false, true) &&
         real("noise_band_split", noise_band_split, noise_band_lo, 1.0, true, true) &&
         real("noise_band_hi", noise_band_hi, noise_band_split, 1.0, true, false) &&
         real("none_ratio", none_ratio, 1.0, inf, false, true) &&
         real("min_excess_reduction", min_excess_reduction, 0.0, 1.0, true, true) &&
         real("min_floor_gain", min_floor_gain, 0.0, inf, false, true) &&
         real("min_delay_samples", min_delay_samples, 0.0, inf, false, true) &&
         integer("swap_passes", swap_passes, 0, 100) &&
         real("min_test_shrink_pct", min_test_shrink_pct, 0.0, 100.0, false, false) &&
         real("max_test_worsening", max_test_worsening, 0.0, inf, false, true) &&
         integer("refit_grid", refit_grid, 2, 1000) &&
         integer("refit_rounds", refit_rounds, 1, 1000) &&
         real("max_condition_samples_pct", max_condition_samples_pct, 0.0, 100.0, true, false) &&
         real("sensor_flat_s", sensor_flat_s, 0.0, inf, true, true);
}

nlohmann::json ToJson(const Options& o) {
  return {{"warmup_s", o.warmup_s},
          {"detrend", o.detrend},
          {"drift_hz", tuning::kDriftHz},
          {"moving_start_fraction", tuning::kMovingStartFraction},
          {"start_travel_factor", tuning::kStartTravelFactor},
          {"start_time_constants", tuning::kStartTimeConstants},
          {"unconfirmed_test_footprint", tuning::kUnconfirmedTestFootprint},
          {"unconfirmed_train_footprint", tuning::kUnconfirmedTrainFootprint},
          {"smooth_hz", o.smooth_hz},
          {"max_smooth_cycles_per_sample", o.max_smooth_cycles_per_sample},
          {"displacement_only_smooth_factor", tuning::kDisplacementOnlySmoothFactor},
          {"vmax_search_factor", tuning::kVmaxSearchFactor},
          {"noise_band_lo", o.noise_band_lo},
          {"noise_band_split", o.noise_band_split},
          {"noise_band_hi", o.noise_band_hi},
          {"noise_psd_segment", tuning::kNoisePsdSegment},
          {"whiteness_lags", tuning::kWhitenessLags},
          {"correlation_max_lag", tuning::kCorrelationMaxLag},
          {"correlation_lag_divisor", tuning::kCorrelationLagDivisor},
          {"none_ratio", o.none_ratio},
          {"min_excess_reduction", o.min_excess_reduction},
          {"min_floor_gain", o.min_floor_gain},
          {"max_effects_per_channel", tuning::kMaxEffectsPerChannel},
          {"min_delay_samples", o.min_delay_samples},
          {"at_bound_fraction", tuning::kAtBoundFraction},
          {"play_creep_slope", tuning::kPlayCreepSlope},
          {"close_call_bic", tuning::kCloseCallBic},
          {"swap_passes", o.swap_passes},
          {"swap_min_gain", tuning::kSwapMinGain},
          {"min_test_shrink_pct", o.min_test_shrink_pct},
          {"max_test_worsening", o.max_test_worsening},
          {"golden_iters_y", tuning::kGoldenItersY},
          {"golden_iters_f", tuning::kGoldenItersF},
          {"refit_golden_iters_y", tuning::kRefitGoldenItersY},
          {"refit_golden_iters_f", tuning::kRefitGoldenItersF},
          {"refit_bracket_factor", tuning::kRefitBracketFactor},
          {"refit_bracket_fraction", tuning::kRefitBracketFraction},
          {"refit_grid", o.refit_grid},
          {"simplex_evals", tuning::kSimplexEvals},
          {"refit_simplex_evals", tuning::kRefitSimplexEvals},
          {"simplex_step_grid_fraction", tuning::kSimplexStepGridFraction},
          {"refit_simplex_step_first", tuning::kRefitSimplexStepFirst},
          {"refit_simplex_step_second", tuning::kRefitSimplexStepSecond},
          {"refit_rel_tol", tuning::kRefitRelTol},
          {"trial_refit_rounds", tuning::kTrialRefitRounds},
          {"refit_rounds", o.refit_rounds},
          {"prune_refit_rounds", tuning::kPruneRefitRounds},
          {"max_condition_samples_pct", o.max_condition_samples_pct},
          {"sensor_flat_s", o.sensor_flat_s}};
}

}  // namespace rths::diagnosis
