#include "monitor/in_process_feed.h"

#include <chrono>

#include "lockstep/abort.h"
#include "lockstep/protocol.h"

namespace rths::monitor {

InProcessFeed::InProcessFeed(LiveView* view, double period_s) : view_(view), period_s_(period_s), ring_(kRingRecords) {}

InProcessFeed::~InProcessFeed() { Stop(); }

void InProcessFeed::Push(const rths::monitor_t& record) {
  if (!ring_.TryPush(record)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

bool InProcessFeed::TakeAbort(std::string* reason) {
  if (!abort_.load(std::memory_order_relaxed) || !abort_.exchange(false)) return false;
  std::lock_guard lock(reason_mutex_);
  *reason = reason_;
  taken_ = true;
  return true;
}

std::string InProcessFeed::RequestAbort(const std::string& reason) {
  const LiveStatus st = view_->Status();
  if (st.run_id == 0) return "the run has not started yet";
  if (st.phase == "completed" || st.phase == "aborted") return "the run has already ended (" + st.phase + ")";
  {
    std::lock_guard lock(reason_mutex_);
    reason_ = reason;
  }
  abort_.store(true);
  return "";
}

void InProcessFeed::Start() {
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] {
    while (!stop_.load()) {
      Drain();
      std::this_thread::sleep_for(std::chrono::duration<double>(period_s_));
    }
    Drain();
  });
}

void InProcessFeed::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void InProcessFeed::Drain() {
  rths::monitor_t record;
  while (ring_.TryPop(&record)) {
    view_->OnRecord(record, WallClock::now());
    if (record.phase != lockstep::kLiveAborted) continue;
    std::lock_guard lock(reason_mutex_);
    // The clock stopped the run at our request: the ABORT a udpm monitor would have heard.
    if (taken_) view_->OnHandshake(record.run_id, lockstep::kAbort, lockstep::kMonitorSender, 0, 0, reason_);
  }
}

}  // namespace rths::monitor
