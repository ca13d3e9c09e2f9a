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
  listener_ = std::make_unique<Listener>(options.lcm_url, &view_);
  server_ = std::make_unique<MonitorServer>(std::move(options.server), &view_,
                                            [this](const std::string& reason) { return listener_->Abort(reason); });
}

Monitor::~Monitor() { Stop(); }

void Monitor::Start() {
  const BlockSignals blocked;
  server_->Start();
  listener_->Start();
}

void Monitor::Stop() {
  server_->Stop();
  listener_->Stop();
}

}  // namespace rths::monitor
