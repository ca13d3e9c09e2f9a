#pragma once
/// @file The clock's live account of a run for the monitor (docs/monitor.md): every committed
/// step's signals and the clock's own latency and deadline figures, decimated into buckets of
/// about 1 / kLivePointsPerSimS simulated seconds, each bucket one rths::monitor_t record. The
/// monitor shows these records as they are, so its counts are the run's (summary.json "realtime").
///
/// The records go to a LiveSink: in this process a lock-free ring that the monitor drains from a
/// thread of its own (monitor/in_process_feed.h: memq and mixed runs), or the RTHS_MONITOR channel
/// of a udpm run (the clock publishes them). Adding a step allocates nothing; a record is made
/// once per bucket.
#include <cstdint>
#include <string>

#include "rths/monitor_t.hpp"

namespace rths::lockstep {

struct RealtimeStats;

/// The channel the clock of a participant process publishes its live records on.
inline constexpr const char* kChMonitor = "RTHS_MONITOR";
/// Live records per simulated second (a bucket is round(1 / (dt * this)) steps, at least 1).
inline constexpr double kLivePointsPerSimS = 100.0;

/// monitor_t.phase.
enum LivePhase : std::int8_t { kLiveRunning = 1, kLiveFinishing = 2, kLiveCompleted = 3, kLiveAborted = 4 };

/// Where the clock's live records go. Push never blocks and never allocates.
class LiveSink {
 public:
  virtual ~LiveSink() = default;
  virtual void Push(const rths::monitor_t& record) = 0;
  /// The operator's stop request, taken once: true and `*reason` set (the clock then aborts the
  /// run as if the monitor had sent ABORT). Called by the clock on every poll: cheap when false.
  virtual bool TakeAbort(std::string* /*reason*/) { return false; }
};

/// The safety monitor's limits the page shows the run's peaks against (docs/safety.md; 0: none).
struct LiveLimits {
  double stroke_mm = 0;     ///< |r|, |u|, |y| [mm]
  double force_kN = 0;      ///< |f| [kN]
  double max_error_mm = 0;  ///< |r - y| [mm]
};

/// The decimator: per bucket the signed peak of each signal and the largest latency, with the
/// clock's totals at the bucket's last step.
class LiveFeed {
 public:
  /// Starts a run (at GO): clears the peaks; `paced` as the clock's RealtimeStats.
  void Start(std::int64_t run_id, std::int64_t n_steps, double dt_s, bool paced, const LiveLimits& limits);
  /// Committed step k: desired r [mm], command u [mm], measured y [mm] and f [kN], current [A],
  /// its latency [s] and whether it missed its deadline; `rt` the clock's totals after it. Pushes
  /// the bucket to `sink` when step k closes it.
  void Add(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN, double i_A, double latency_s,
           bool missed, const RealtimeStats& rt, LiveSink* sink);
  /// Several actuators (n >= 1 values each, e.g. desired_t.r_act_mm): folds every actuator's
  /// |r|, |u|, |y| and |r - y| of the step into the run's peaks against the safety limits, as the
  /// safety monitor checks every actuator (the plotted signals stay the scalars: actuator 1).
  /// Call with the step's Add. Allocates nothing.
  void KeepActuatorPeaks(int n, const double* r_mm, const double* u_mm, const double* y_mm);
  /// Pushes what the open bucket holds, then a record of `phase` (the totals unchanged).
  void Phase(LivePhase phase, LiveSink* sink);
  std::int32_t bucket_steps() const { return record_.bucket_steps; }

 private:
  void ClearBucket();
  void PushBucket(LiveSink* sink);

  rths::monitor_t record_{};  ///< the open bucket; its totals are the newest step's
  std::int64_t in_bucket_ = 0;
};

}  // namespace rths::lockstep
