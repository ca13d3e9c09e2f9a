#pragma once
/// @file What the live monitor knows of a run (docs/monitor.md): the run's phase from its
/// handshake, the step counter and rate, the lateness of paced steps as this listener sees them,
/// and a decimated history of r, u, y, the tracking error r - y, the force and the current.
///
/// Fed by a lossy listener (monitor/listener.h): a lost message leaves a gap in the plots and a
/// count, never a wait. Every method locks one mutex; a browser reads what is new with Since().
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rths::monitor {

using WallClock = std::chrono::steady_clock;

/// How the view decimates and what it assumes of the run.
struct LiveViewOptions {
  /// Plotted points per second of simulated time [1/s]: a bucket is round(1 / (dt * this)) steps
  /// (at least 1); each signal keeps its value of largest magnitude in the bucket, so a peak is
  /// never decimated away.
  double points_per_sim_s = 100.0;
  std::size_t capacity = 1 << 16;  ///< points kept for a browser that connects late (the newest)
  /// The run is paced to the wall clock (`run --realtime`): report each step's lateness and count
  /// the steps seen completing after their deadline. Unpaced: the lateness is not shown.
  bool paced = false;
};

/// One plotted point: a bucket's peaks (NaN where no step of the bucket had the signal).
struct LivePoint {
  double t_s = 0;          ///< simulated time of the bucket's last step, k * dt [s]
  double r_mm = 0;         ///< desired displacement [mm]
  double u_mm = 0;         ///< command [mm]
  double y_mm = 0;         ///< measured displacement [mm]
  double e_mm = 0;         ///< tracking error r - y [mm]
  double f_kN = 0;         ///< measured force [kN]
  double i_A = 0;          ///< damper current [A]
  double latency_ms = 0;   ///< paced: the bucket's largest step latency as heard [ms] (NaN unpaced)
};

/// The run's state as the monitor sees it.
struct LiveStatus {
  std::int64_t run_id = 0;
  std::string phase = "waiting";  ///< waiting | starting | running | finishing | completed | aborted
  std::string abort_by, abort_reason;  ///< phase aborted: the ABORT's sender and reason
  std::int64_t n_steps = 0;
  double dt_s = 0;
  std::int64_t last_k = -1;       ///< the newest step measured
  double steps_per_s = 0;         ///< over the last second of wall time [1/s]
  std::int64_t steps_seen = 0;    ///< measured steps heard (a lost datagram: a step not seen)
  bool paced = false;
  /// Paced runs, as this listener hears them (the clock's own figures are in summary.json): a
  /// step's latency is its measured_t's arrival minus its desired_t's; its deadline is t0 + (k+1)
  /// dt, t0 the earliest arrival of desired_t k minus k dt; a miss is a measured_t after it.
  double latency_ms = 0;          ///< the newest step's latency [ms]
  double latency_max_ms = 0;      ///< the largest so far [ms]
  std::int64_t misses = 0;        ///< steps heard completing after their deadline
  std::int64_t longest_miss_run = 0;  ///< most misses in a row
};

/// The state of one run at a time: a handshake with a new run id starts over.
class LiveView {
 public:
  explicit LiveView(LiveViewOptions options = {});

  /// A handshake message (phases of lockstep/protocol.h): REQUEST/HELLO/GO start or identify the
  /// run, GO sets its time origin, DONE/CLOSE end it, ABORT records who stopped it and why.
  void OnHandshake(std::int64_t run_id, int phase, const std::string& sender, std::int64_t n_steps, double dt_s,
                   const std::string& reason);
  /// desired_t of step k: r_k [mm]; `now` its arrival (the step's release, paced).
  void OnDesired(std::int64_t run_id, std::int64_t k, double r_mm, WallClock::time_point now);
  /// command_t of step k: u_k [mm].
  void OnCommand(std::int64_t run_id, std::int64_t k, double u_mm);
  /// measured_t of step k: y_k [mm], f_k [kN], current [A]; `now` its arrival. Step k - kJoinLag
  /// is then joined with its r and u and goes into its bucket.
  void OnMeasured(std::int64_t run_id, std::int64_t k, double y_mm, double f_kN, double i_A,
                  WallClock::time_point now);

  LiveStatus Status() const;
  /// The points after `cursor` (an index that only grows; the oldest kept if it fell out), at most
  /// `max_points`, and the status, as JSON: {"status": {...}, "cursor": next, "points": [[t, r, u,
  /// y, e, f, i, late], ...]} (NaN as null).
  nlohmann::json Since(std::int64_t cursor, std::size_t max_points = 5000) const;
  /// Points made so far (the cursor after the newest).
  std::int64_t PointsMade() const;

  /// Steps a measured message waits for its step's r and u (arrivals on other sockets may be out
  /// of order by a few steps).
  static constexpr std::int64_t kJoinLag = 4;

 private:
  struct Slot {
    std::int64_t k = -1;
    double r = 0, u = 0, y = 0, f = 0, i = 0, latency_ms = 0;
    WallClock::time_point released{};
    bool has_r = false, has_u = false, has_y = false;
  };
  static constexpr std::size_t kSlots = 256;

  void StartRun(std::int64_t run_id, std::int64_t n_steps, double dt_s);
  void SetStep(double dt_s);
  Slot& SlotOf(std::int64_t k);
  /// Puts step k's slot into the open bucket (closing it when full).
  void Join(std::int64_t k);
  void CloseBucket();
  /// Joins every step still waiting (the run ended).
  void Flush();
  void UpdateRate(WallClock::time_point now);

  LiveViewOptions options_;
  mutable std::mutex mutex_;
  LiveStatus status_;
  double t0_s_ = 0;                 ///< paced: the release schedule's origin [s of WallClock]
  bool have_t0_ = false;
  std::int64_t bucket_steps_ = 1;
  std::vector<Slot> slots_;
  std::int64_t next_join_ = 0;      ///< the next step to join
  LivePoint open_{};                ///< the bucket being filled
  std::int64_t open_count_ = 0;     ///< steps in it
  std::int64_t open_bucket_ = -1;   ///< its index, k / bucket_steps_
  std::vector<LivePoint> ring_;     ///< the newest points (ring of options_.capacity)
  std::int64_t made_ = 0;           ///< points made since the run started
  std::int64_t miss_run_ = 0;
  WallClock::time_point rate_t_{};  ///< the rate's window start
  std::int64_t rate_k_ = -1;
};

}  // namespace rths::monitor
