#include "monitor/monitor.h"

#include <signal.h>

namespace rths::monitor {
namespace {

/// Blocks every signal in the calling thread while it lives, so the threads started meanwhile
/// (the listener's, LCM's receive thread, the web server's pool) inherit a full mask: a signal for
/// the process (SIGCHLD, SIGINT) is then never taken by them, and the supervisor's signalfd sees it.
class BlockSignals {
 public:
  BlockSignals() {
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old_);
  }
  ~BlockSignals() { pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  BlockSignals(const BlockSignals&) = delete;
  BlockSignals& operator=(const BlockSignals&) = delete;

 private:
  sigset_t old_;
};

}  // namespace

Monitor::Monitor(MonitorOptions options) : view_(options.view) {
  const BlockSignals blocked;
  AbortFunction abort;
  if (options.lcm_url.empty()) {
    feed_ = std::make_unique<InProcessFeed>(&view_);
    abort = [this](const std::string& reason) { return feed_->RequestAbort(reason); };
  } else {
    listener_ = std::make_unique<Listener>(options.lcm_url, &view_);
    abort = [this](const std::string& reason) { return listener_->Abort(reason); };
  }
  server_ = std::make_unique<MonitorServer>(std::move(options.server), &view_, std::move(abort));
}

Monitor::~Monitor() { Stop(); }

void Monitor::Start() {
  const BlockSignals blocked;
  server_->Start();
  if (listener_) listener_->Start();
  if (feed_) feed_->Start();
}

void Monitor::Stop() {
  server_->Stop();
  if (listener_) listener_->Stop();
  if (feed_) feed_->Stop();
}

void Monitor::OnEnd(std::int64_t run_id, const std::string& status, const std::string& by,
                    const std::string& reason, std::int64_t steps) {
  if (feed_) feed_->Stop();  // every record the run made is in the view first
  view_.OnEnd(run_id, status, by, reason, steps);
}

}  // namespace rths::monitor
