#pragma once
/// @file What the live monitor knows of a run (docs/monitor.md): the run's phase, and the clock's
/// own account of it (lockstep/live_feed.h: one rths::monitor_t record per bucket of about 10 ms
/// of simulated time): the step counter, the latency and deadline misses as the clock measures and
/// counts them (so the page agrees with summary.json "realtime"), the safety limits and the run's
/// peaks against them, and a history of the buckets' peaks of r, u, y, r - y, f and the current.
///
/// Fed by a lossy listener on a udpm run (monitor/listener.h) or by the run's own process
/// (monitor/in_process_feed.h): a lost record leaves a gap in the plots and a count, never a wait.
/// Every method locks one mutex; a browser reads what is new with Since().
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rths/monitor_t.hpp"

namespace rths::monitor {

using WallClock = std::chrono::steady_clock;

struct LiveViewOptions {
  std::size_t capacity = 1 << 16;  ///< points kept for a browser that connects late (the newest)
};

/// One plotted point: a bucket's peaks, as the clock made them.
struct LivePoint {
  double t_s = 0;          ///< simulated time of the bucket's last step, k * dt [s]
  double r_mm = 0;         ///< desired displacement [mm]
  double u_mm = 0;         ///< command [mm]
  double y_mm = 0;         ///< measured displacement [mm]
  double e_mm = 0;         ///< tracking error r - y [mm]
  double f_kN = 0;         ///< measured force [kN]
  double i_A = 0;          ///< damper current [A]
  double latency_ms = 0;   ///< the bucket's largest step latency, as the clock measures it [ms]
  std::int32_t misses = 0; ///< paced: the bucket's steps that completed after their deadline
};

/// The run's state as the monitor sees it.
struct LiveStatus {
  std::int64_t run_id = 0;
  std::string phase = "waiting";  ///< waiting | starting | running | finishing | completed | aborted
  std::string abort_by, abort_reason;  ///< phase aborted: the ABORT's sender and reason
  std::int64_t n_steps = 0;
  double dt_s = 0;
  std::int64_t last_k = -1;       ///< the newest committed step heard of
  double steps_per_s = 0;         ///< over the last half second or more of wall time [1/s]
  std::int64_t records_heard = 0;     ///< bucket records received
  std::int64_t records_expected = 0;  ///< bucket records the clock has made up to last_k
  bool paced = false;
  /// The clock's figures (lockstep/realtime.h): a step's latency is from its release to its
  /// barrier being complete; a miss is a step complete after its deadline t0 + (k+1) dt.
  double latency_ms = 0;          ///< the newest step's latency [ms]
  double latency_max_ms = 0;      ///< the largest so far [ms]
  std::int64_t misses = 0;        ///< paced: steps completed after their deadline
  std::int64_t longest_miss_run = 0;  ///< paced: most misses in a row
  /// The safety monitor's limits (0: none) and the run's peaks so far.
  double stroke_mm = 0, force_kN = 0, max_error_mm = 0;
  double peak_disp_mm = 0, peak_force_kN = 0, peak_error_mm = 0;
  /// The run's supervisor has reported its end (OnEnd): last_k + 1 is then summary.json's `steps`
  /// (the log's complete steps), which may be one more than the clock had committed when it was
  /// stopped.
  bool ended = false;
};

/// The state of one run at a time: a new run id starts over.
class LiveView {
 public:
  explicit LiveView(LiveViewOptions options = {});

  /// A handshake message (phases of lockstep/protocol.h; a udpm run): REQUEST starts or
  /// identifies the run, GO runs it, DONE/CLOSE end it, ABORT records who stopped it and why.
  void OnHandshake(std::int64_t run_id, int phase, const std::string& sender, std::int64_t n_steps, double dt_s,
                   const std::string& reason);
  /// A record of the clock's (lockstep/live_feed.h); `now` its arrival.
  void OnRecord(const rths::monitor_t& record, WallClock::time_point now);
  /// The run ended as its supervisor reports it (a monitor in the run's own process): `status` as
  /// summary.json's ("completed", "aborted", ...), `by` and `reason` of an abort, `steps` its
  /// complete steps.
  void OnEnd(std::int64_t run_id, const std::string& status, const std::string& by, const std::string& reason,
             std::int64_t steps);

  LiveStatus Status() const;
  /// The points after `cursor` (an index that only grows; the oldest kept if it fell out), at most
  /// `max_points`, and the status, as JSON: {"status": {...}, "cursor": next, "points": [[t, r, u,
  /// y, e, f, i, latency, misses], ...]}.
  nlohmann::json Since(std::int64_t cursor, std::size_t max_points = 5000) const;
  /// Points made so far (the cursor after the newest).
  std::int64_t PointsMade() const;

 private:
  void StartRun(std::int64_t run_id, std::int64_t n_steps, double dt_s);
  void UpdateRate(WallClock::time_point now);

  LiveViewOptions options_;
  mutable std::mutex mutex_;
  LiveStatus status_;
  std::vector<LivePoint> ring_;     ///< the newest points (ring of options_.capacity)
  std::int64_t made_ = 0;           ///< points made since the run started
  WallClock::time_point rate_t_{};  ///< the rate's window start
  std::int64_t rate_k_ = -1;
};

}  // namespace rths::monitor
