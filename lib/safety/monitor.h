#pragma once
/// @file The safety monitor (docs/safety.md). The clock runs it on every committed step, so a
/// run that leaves the rig's limits is stopped cleanly — with a reason, exit code 6 and the
/// log intact up to the step that tripped — never by a crash, NaN or overflow.
#include <array>
#include <cstdint>
#include <string_view>

#include <fmt/format.h>

#include "scenario/scenario.h"

namespace rths::safety {

class Monitor {
 public:
  /// Throws rths::Error if the window is shorter than one step.
  Monitor(const scenario::SafetyConfig& cfg, double dt_s);

  /// Checks the signals of step k, in order of k: desired r_k [mm], command u_k [mm],
  /// measured y_k [mm] and f_k [kN]. Returns "" while every limit holds, else the reason
  /// (valid until the next call). Allocates nothing.
  std::string_view Check(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN);

 private:
  /// Formats the stop reason into the preallocated buffer.
  template <class... Args>
  std::string_view Trip(std::int64_t k, fmt::format_string<Args...> what, Args&&... args) {
    auto r = fmt::format_to_n(reason_.data(), reason_.size() - 1, "safety: step {} (t = {:.4f} s): ", k,
                              static_cast<double>(k) * dt_s_);
    const auto used = static_cast<std::size_t>(r.out - reason_.data());
    auto w = fmt::format_to_n(r.out, reason_.size() - 1 - used, what, std::forward<Args>(args)...);
    *w.out = '\0';
    return {reason_.data(), static_cast<std::size_t>(w.out - reason_.data())};
  }

  const scenario::SafetyConfig cfg_;
  const double dt_s_;
  const std::int64_t window_steps_;
  double window_peak_ = 0.0;      ///< peak |r - y| in the current window [mm]
  double previous_peak_ = 0.0;    ///< peak of the previous window [mm]
  std::int64_t in_window_ = 0;
  int growing_windows_ = 0;       ///< consecutive windows that grew by growth_factor
  std::array<char, 512> reason_{};
};

}  // namespace rths::safety
