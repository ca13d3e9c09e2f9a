#pragma once
/// @file The safety monitor (docs/safety.md). The clock runs it on every committed step, so a
/// run that leaves the rig's limits is stopped cleanly — with a reason, exit code 6 and the
/// log intact up to the step that tripped — never by a crash, NaN or overflow.
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include <fmt/format.h>


namespace rths::safety {

/// Safety monitor (docs/safety.md): the clock stops the run, cleanly, when a limit is left.
/// Defaults are the paper's actuator ratings (556 kN, +/-152.4 mm stroke).
struct SafetyConfig {
  bool enabled = true;
  double stroke_mm = 152.4;        ///< |r|, |u|, |y| must stay within, (0, 10000]
  double force_kN = 556.0;         ///< |f| must stay within, (0, 1e6]
  double max_error_mm = 25.0;      ///< |r - y| must stay within, (0, 10000]
  /// Divergence: the peak |r - y| over consecutive windows of growth_window_s grows by at least
  /// growth_factor every window for growth_windows windows, above growth_floor_mm.
  double growth_window_s = 0.25;   ///< (0, 10]; at least one period of the oscillation to watch
  double growth_factor = 1.3;      ///< (1, 1000]
  int growth_windows = 4;          ///< [2, 1000]
  double growth_floor_mm = 0.5;    ///< (0, 10000]
  bool operator==(const SafetyConfig&) const = default;
};

class Monitor {
 public:
  /// For `n_actuators` (>= 1) actuators, each with its own divergence window. Throws rths::Error
  /// if the window is shorter than one step or n_actuators < 1.
  Monitor(const safety::SafetyConfig& cfg, double dt_s, int n_actuators = 1);

  /// Checks the signals of step k of the one actuator, in order of k: desired r_k [mm], command
  /// u_k [mm], measured y_k [mm] and f_k [kN]. Returns "" while every limit holds, else the reason
  /// (valid until the next call). Allocates nothing.
  std::string_view Check(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN);

  /// The same for every actuator i (r_mm[i], u_mm[i], y_mm[i]; n_actuators each) and the measured
  /// force f_kN: every limit is checked on every actuator, in the order of Check, and the reason
  /// names the actuator ("actuator 2: ...") when there are several. Allocates nothing.
  std::string_view CheckActuators(std::int64_t k, const double* r_mm, const double* u_mm, const double* y_mm,
                                  double f_kN);

  int n_actuators() const { return static_cast<int>(windows_.size()); }

 private:
  /// One actuator's divergence watch: the window peaks of |r - y|.
  struct Window {
    double peak = 0.0;           ///< peak |r - y| in the current window [mm]
    double previous_peak = 0.0;  ///< peak of the previous window [mm]
    int growing = 0;             ///< consecutive windows that grew by growth_factor
  };

  /// Formats the stop reason into the preallocated buffer, after "actuator i: " when there are
  /// several actuators and the limit is one actuator's (actuator >= 0).
  template <class... Args>
  std::string_view Trip(std::int64_t k, int actuator, fmt::format_string<Args...> what, Args&&... args) {
    auto r = fmt::format_to_n(reason_.data(), reason_.size() - 1, "safety: step {} (t = {:.4f} s): ", k,
                              static_cast<double>(k) * dt_s_);
    if (windows_.size() > 1 && actuator >= 0) r = fmt::format_to_n(r.out, reason_.size() - 1 - Used(r.out), "actuator {}: ", actuator + 1);
    auto w = fmt::format_to_n(r.out, reason_.size() - 1 - Used(r.out), what, std::forward<Args>(args)...);
    *w.out = '\0';
    return {reason_.data(), Used(w.out)};
  }
  std::size_t Used(const char* end) const { return static_cast<std::size_t>(end - reason_.data()); }

  const safety::SafetyConfig cfg_;
  const double dt_s_;
  const std::int64_t window_steps_;
  std::vector<Window> windows_;   ///< one per actuator, sized at construction
  std::int64_t in_window_ = 0;    ///< steps in the current window (the same for every actuator)
  std::array<char, 512> reason_{};
};

}  // namespace rths::safety
