#pragma once
/// @file Real-time paced mode (docs/realtime.md): the clock's pacing knobs, the per-step latency
/// and deadline-miss statistics it keeps, and the process set-up (SCHED_FIFO, mlockall) every
/// participant process tries when pacing is on.
///
/// Step k is released (desired_t k published) at t_k = t0 + k dt on CLOCK_MONOTONIC, t0 the
/// moment of GO, waiting with clock_nanosleep(TIMER_ABSTIME) (absolute deadlines: no drift). Its
/// latency is the time from that publication to its barrier being complete (every answer of
/// step k in, the logger's ack included). Step k misses its deadline when its barrier completes
/// after t_{k+1} = t0 + (k+1) dt. A late step is not skipped: the next one is released at once
/// (steps are never skipped), so a run that falls behind catches up to the wall clock.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rths::lockstep {

/// Real-time paced mode (docs/realtime.md; `rths run --realtime` turns it on): the clock issues
/// step k at t0 + k dt of the wall clock (absolute deadlines) and counts the steps that complete
/// after their deadline t0 + (k+1) dt.
struct RealtimeConfig {
  bool enabled = false;                    ///< pace the clock to wall time
  /// Miss policy: 0 = continue and count; N > 0 = stop the run (exit 8) after N consecutive
  /// deadline misses, [0, 1e9].
  std::int64_t max_consecutive_misses = 0;
  bool sched_fifo = true;                  ///< try SCHED_FIFO for every participant process
  int priority = 80;                       ///< its SCHED_FIFO priority, [1, 99]
  bool lock_memory = true;                 ///< try mlockall(MCL_CURRENT | MCL_FUTURE)
  /// Busy-wait the last spin_us [us] before each step's release instead of sleeping through it
  /// (the wake-up's lateness is then the spin loop's, not the timer's), [0, 5000]; 0: off.
  double spin_us = 0;
  /// Pin every rths process of the run to this CPU (sched_setaffinity), [-1, 1023]; -1: no pinning.
  /// A memq or mixed run is one process; on udpm each participant process is pinned to it.
  int cpu = -1;
  bool operator==(const RealtimeConfig&) const = default;
};

/// How the clock paces steps (from the scenario's [realtime] table).
struct Pacing {
  bool enabled = false;
  double period_s = 0.0;  ///< dt [s]
  /// Stop the run (exit kExitRealtime) after this many consecutive misses; 0 = never.
  std::int64_t max_consecutive_misses = 0;
  double spin_s = 0.0;  ///< busy-wait this long before each release [s] (RealtimeConfig::spin_us)
  bool operator==(const Pacing&) const = default;
};

/// Durations in log-spaced bins: 100 per decade from 1 us to 100 s (neighbouring bin edges 2.3 %
/// apart), plus an underflow and an overflow bin. Adding allocates nothing.
class LatencyHistogram {
 public:
  static constexpr int kPerDecade = 100;
  static constexpr int kDecades = 8;
  static constexpr double kLowestS = 1e-6;
  static constexpr int kBins = kPerDecade * kDecades + 2;  ///< [0] underflow, [kBins-1] overflow

  void Add(double seconds);
  std::int64_t count() const { return count_; }
  double max_s() const { return max_s_; }
  /// The q-quantile (0 < q <= 1) [s]: the upper edge of the bin that holds it (at most max_s()),
  /// so it is never below the true value and at most 2.3 % above it. 0 if empty.
  double Quantile(double q) const;
  /// Lower and upper edge of bin i [s] (bin 0: [0, 1 us); the last bin: [100 s, inf)).
  static double LowerEdge(int i);
  static double UpperEdge(int i);
  std::int64_t bin(int i) const { return bins_[i]; }

 private:
  std::array<std::int64_t, kBins> bins_{};
  std::int64_t count_ = 0;
  double max_s_ = 0.0;
};

/// What the clock measured of a run's pace.
struct RealtimeStats {
  bool paced = false;
  double period_s = 0.0;
  std::int64_t steps = 0;                   ///< steps whose barrier completed
  std::int64_t misses = 0;                  ///< of them, completed after their deadline
  std::int64_t max_consecutive_misses = 0;  ///< longest run of consecutive misses
  std::int64_t first_miss_step = -1;
  LatencyHistogram latency;                 ///< request -> barrier complete, every step
  /// How late step releases were (wake-up jitter; catching up after a miss) [s]: max.
  double max_release_late_s = 0.0;
  /// The latency over the run (paced runs): per window of `window_steps` steps (about
  /// kLatencyWindowS), the largest step latency [s] and the misses in it. Sized before step 0 by
  /// SizeWindows; AccountStep only writes into them.
  std::int64_t window_steps = 0;
  std::vector<float> window_max_s;
  std::vector<std::int32_t> window_misses;

  /// The windows' length aimed at [s].
  static constexpr double kLatencyWindowS = 0.1;
  /// Sizes the windows for `n_steps` steps of `period_s` (allocates; before step 0).
  void SizeWindows(std::int64_t n_steps, double period_s);
  /// Step k's latency [s] and whether it missed, into its window (allocates nothing).
  void AddToWindow(std::int64_t k, double latency_s, bool missed) {
    if (window_steps <= 0) return;
    const auto w = static_cast<std::size_t>(k / window_steps);
    if (w >= window_max_s.size()) return;
    if (latency_s > window_max_s[w]) window_max_s[w] = static_cast<float>(latency_s);
    if (missed) ++window_misses[w];
  }
};

/// What a process achieved when it tried to run in real time.
struct RealtimeSetup {
  bool tried = false;
  bool fifo = false;        ///< running under SCHED_FIFO
  int priority = 0;         ///< ... at this priority
  bool memory_locked = false;
  int cpu = -1;             ///< pinned to this CPU (-1: not pinned)
  std::string note;         ///< what was not permitted, and why ("" if everything worked)
};

/// Tries SCHED_FIFO at `priority` (if `fifo`), mlockall(MCL_CURRENT | MCL_FUTURE) (if `lock`) and
/// pinning to `cpu` (if >= 0) for the calling process; says plainly what was not permitted (errno
/// text and what grants it).
RealtimeSetup EnterRealtime(bool fifo, int priority, bool lock, int cpu = -1);
/// EnterRealtime with the keys of a scenario's [realtime] table.
inline RealtimeSetup EnterRealtime(const RealtimeConfig& r) {
  return EnterRealtime(r.sched_fifo, r.priority, r.lock_memory, r.cpu);
}

}  // namespace rths::lockstep
