#include "safety/monitor.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::safety {

Monitor::Monitor(const safety::SafetyConfig& cfg, double dt_s, int n_actuators)
    : cfg_(cfg), dt_s_(dt_s), window_steps_(std::llround(cfg.growth_window_s / dt_s)) {
  if (window_steps_ < 1) throw Error("safety.growth_window_s", "shorter than one step");
  if (n_actuators < 1) throw Error("safety", fmt::format("{} actuators to watch; at least 1", n_actuators));
  windows_.resize(static_cast<std::size_t>(n_actuators));
}

std::string_view Monitor::Check(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN) {
  return CheckActuators(k, &r_mm, &u_mm, &y_mm, f_kN);
}

std::string_view Monitor::CheckActuators(std::int64_t k, const double* r, const double* u, const double* y,
                                         double f_kN) {
  if (!cfg_.enabled) return {};
  const int n = n_actuators();
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(r[i]) || !std::isfinite(u[i]) || !std::isfinite(y[i]) || !std::isfinite(f_kN)) {
      return Trip(k, i, "a signal is not finite (r = {}, u = {}, y = {} mm, f = {} kN)", r[i], u[i], y[i], f_kN);
    }
  }
  const double s = cfg_.stroke_mm;
  for (int i = 0; i < n; ++i) {
    if (std::abs(r[i]) > s) return Trip(k, i, "desired displacement |r| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(r[i]), s);
    if (std::abs(u[i]) > s) return Trip(k, i, "actuator command |u| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(u[i]), s);
    if (std::abs(y[i]) > s) return Trip(k, i, "measured displacement |y| = {:.2f} mm exceeds the stroke {} mm (safety.stroke_mm)", std::abs(y[i]), s);
  }
  if (std::abs(f_kN) > cfg_.force_kN) {
    return Trip(k, -1, "measured force |f| = {:.1f} kN exceeds the actuator's {} kN (safety.force_kN)", std::abs(f_kN), cfg_.force_kN);
  }
  for (int i = 0; i < n; ++i) {
    const double e = std::abs(r[i] - y[i]);
    if (e > cfg_.max_error_mm) {
      return Trip(k, i, "tracking error |r - y| = {:.2f} mm exceeds {} mm (safety.max_error_mm)", e, cfg_.max_error_mm);
    }
    windows_[static_cast<std::size_t>(i)].peak = std::max(windows_[static_cast<std::size_t>(i)].peak, e);
  }
  // Divergence: an actuator's window peak of |r - y| grows geometrically, window after window.
  if (++in_window_ < window_steps_) return {};
  in_window_ = 0;
  int diverging = -1;
  for (int i = 0; i < n; ++i) {
    Window& w = windows_[static_cast<std::size_t>(i)];
    const bool grew = w.peak >= cfg_.growth_floor_mm && w.peak >= cfg_.growth_factor * w.previous_peak;
    w.growing = grew ? w.growing + 1 : 0;
    w.previous_peak = w.peak;
    w.peak = 0.0;
    if (diverging < 0 && w.growing >= cfg_.growth_windows) diverging = i;
  }
  if (diverging >= 0) {
    return Trip(k, diverging,
                "tracking error diverging: its peak grew by at least {}x in each of the last {} windows of {} s, "
                "to {:.2f} mm (safety.growth_*)",
                cfg_.growth_factor, cfg_.growth_windows, cfg_.growth_window_s,
                windows_[static_cast<std::size_t>(diverging)].previous_peak);
  }
  return {};
}

}  // namespace rths::safety
