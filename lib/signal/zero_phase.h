#pragma once
/// @file Zero-phase low-pass filtering of a whole record (offline: allocates): a Butterworth
/// low-pass (butterworth.h) run forward, then backward, over the record extended past its ends, so
/// that the result has no lag (|H|^2 overall, phase 0). Used for the damper fits' smoothed
/// velocity (ident/damper_fit.h SmoothVelocity) and the diagnosis's smoothed motion and drift
/// (diagnosis/channel_models.h).
#include <cstddef>
#include <span>
#include <vector>

namespace rths::signal {

/// How ZeroPhaseLowpass extends a signal x_0 .. x_{n-1} past its ends.
enum class Reflection {
  kOdd,   ///< about the end samples: 2 x_0 - x_j before, 2 x_{n-1} - x_{n-1-j} after (keeps the slope)
  kEven,  ///< mirrored: x_j before, x_{n-1-j} after (keeps the level; no step from a noisy end sample)
};

/// The state each pass of ZeroPhaseLowpass starts from.
enum class FilterStart {
  kAtRest,        ///< all registers zero
  kSteadyState,   ///< the steady state of the pass's first (extended) value: 400 samples of it run first
};

/// x through a Butterworth low-pass of `order` at fc_hz (sample step dt_s [s]) forward, then
/// backward (zero phase, |H|^2 of the order's filter overall), over x extended at both ends by
/// `pad` samples (at most n - 1) as `reflection` says, each pass starting as `start` says; the n
/// samples of x's span returned (none for none). Throws rths::Error as ButterworthLowpass does
/// (fc_hz must be in (0, 0.5 / dt_s)).
std::vector<double> ZeroPhaseLowpass(std::span<const double> x, double dt_s, double fc_hz, int order,
                                     std::size_t pad, Reflection reflection,
                                     FilterStart start = FilterStart::kAtRest);

}  // namespace rths::signal
