#pragma once
/// @file The live monitor's ear on a udpm run (docs/monitor.md): an ordinary LCM listener on the
/// run's handshake port that hears the handshake and the clock's live records (RTHS_MONITOR,
/// lockstep/live_feed.h) and feeds a LiveView from a thread of its own. It hears none of the
/// per-step channels and never sends on them, so it cannot slow the lockstep loop down or stop
/// it, except by Abort().
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "monitor/live_view.h"

namespace rths::monitor {

class Listener {
 public:
  /// Opens the run's udpm `url` (a plain LCM URL, or ours with port_per_channel=1: then the
  /// handshake's port). Throws Error naming the URL if it cannot.
  Listener(const std::string& url, LiveView* view);
  ~Listener();
  Listener(const Listener&) = delete;
  Listener& operator=(const Listener&) = delete;

  /// Starts listening in a thread of its own (until Stop() or destruction).
  void Start();
  void Stop();

  /// Stops the run being watched: ABORT from "monitor" with `reason` (lockstep/abort.h). Returns ""
  /// on success, else why not (no run heard yet, the run already ended, the URL failed).
  std::string Abort(const std::string& reason);

  const std::string& url() const { return url_; }

 private:
  void Loop();
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  std::string url_;
  LiveView* view_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace rths::monitor
