#include "safety/monitor.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::safety {

Monitor::Monitor(const safety::SafetyConfig& cfg, double dt_s)
    : cfg_(cfg), dt_s_(dt_s), window_steps_(std::llround(cfg.growth_window_s / dt_s)) {
  if (window_steps_ < 1) throw Error("safety.growth_window_s", "shorter than one step");
}

std::string_view Monitor::Check(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN) {
  if (!cfg_.enabled) return {};
  if (!std::isfinite(r_mm) || !std::isfinite(u_mm) || !std::isfinite(y_mm) || !std::isfinite(f_kN)) {
    return Trip(k, "a signal is not finite (r = {}, u = {}, y = {} mm, f = {} kN)", r_mm, u_mm, y_mm, f_kN);
  }
  const double s = cfg_.stroke_mm;
  if (std::abs(r_mm) > s) return Trip(k, "desired displacement |r| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(r_mm), s);
  if (std::abs(u_mm) > s) return Trip(k, "actuator command |u| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(u_mm), s);
  if (std::abs(y_mm) > s) return Trip(k, "measured displacement |y| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(y_mm), s);
  if (std::abs(f_kN) > cfg_.force_kN) {
    return Trip(k, "measured force |f| = {:.1f} kN exceeds the actuator's {} kN (safety.force_kN)", std::abs(f_kN), cfg_.force_kN);
  }
  const double e = std::abs(r_mm - y_mm);
  if (e > cfg_.max_error_mm) {
    return Trip(k, "tracking error |r - y| = {:.2f} mm exceeds {} mm (safety.max_error_mm)", e, cfg_.max_error_mm);
  }
  // Divergence: the window peak of |r - y| grows geometrically, window after window.
  window_peak_ = std::max(window_peak_, e);
  if (++in_window_ == window_steps_) {
    const bool grew = window_peak_ >= cfg_.growth_floor_mm && window_peak_ >= cfg_.growth_factor * previous_peak_;
    growing_windows_ = grew ? growing_windows_ + 1 : 0;
    previous_peak_ = window_peak_;
    window_peak_ = 0.0;
    in_window_ = 0;
    if (growing_windows_ >= cfg_.growth_windows) {
      return Trip(k, "tracking error diverging: its peak grew by at least {}x in each of the last {} windows of {} s, "
                 "to {:.2f} mm (safety.growth_*)",
                 cfg_.growth_factor, cfg_.growth_windows, cfg_.growth_window_s, previous_peak_);
    }
  }
  return {};
}

}  // namespace rths::safety
