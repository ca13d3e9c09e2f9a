#pragma once
/// @file The live monitor fed by the run's own process (docs/monitor.md): a memq or mixed run's
/// clock pushes its records (lockstep/live_feed.h) into a lock-free ring, and a thread of the
/// monitor's drains it into the LiveView, so the step never waits for the monitor or the browser.
/// A full ring (the drain fell behind by more than kRingRecords) drops the record and counts it.
/// The Abort button sets a flag the clock reads on its next poll.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "core/spsc_ring.h"
#include "lockstep/live_feed.h"
#include "monitor/live_view.h"

namespace rths::monitor {

class InProcessFeed final : public lockstep::LiveSink {
 public:
  static constexpr std::size_t kRingRecords = 4096;
  /// Drains into `view` every `period_s` [s] once Start()ed.
  explicit InProcessFeed(LiveView* view, double period_s = 0.02);
  ~InProcessFeed() override;
  InProcessFeed(const InProcessFeed&) = delete;
  InProcessFeed& operator=(const InProcessFeed&) = delete;

  /// The clock's side (the run's thread): never blocks, allocates nothing.
  void Push(const rths::monitor_t& record) override;
  bool TakeAbort(std::string* reason) override;

  /// The page's Abort: "" if the run will stop, else why not (no run yet, already ended).
  std::string RequestAbort(const std::string& reason);
  void Start();
  /// Drains what is left and stops the thread.
  void Stop();
  std::int64_t dropped() const { return dropped_.load(); }

 private:
  void Drain();

  LiveView* view_;
  const double period_s_;
  SpscRing<rths::monitor_t> ring_;
  std::atomic<std::int64_t> dropped_{0};
  std::atomic<bool> abort_{false};
  std::mutex reason_mutex_;
  std::string reason_;
  bool taken_ = false;  ///< the clock took the abort (guarded by reason_mutex_)
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace rths::monitor
