#include "supervisor/teardown.h"

#include <algorithm>
#include <csignal>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "lockstep/abort.h"

namespace rths::supervisor {

char ProcessState(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = all.rfind(')');
  return close != std::string::npos && close + 2 < all.size() ? all[close + 2] : 0;
}

void Teardown::Start(const std::string& reason) {
  if (started_) return;
  started_ = true;
  noticed_ = Clock::now();
  lockstep::BroadcastAbort(url_, run_id_, "supervisor", reason);
  term_at_ = noticed_ + kGraceAbort;
}

int Teardown::WaitMs(int idle_ms) const {
  const auto now = Clock::now();
  auto until = [&](Clock::time_point t) {
    return static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(t - now).count());
  };
  int ms = idle_ms;
  if (started_ && !termed_) ms = until(term_at_);
  if (termed_ && !killed_) ms = until(kill_at_);
  return std::max(ms, 0);
}

int Teardown::Due() {
  const auto t = Clock::now();
  if (started_ && !termed_ && t >= term_at_) {
    termed_ = true;
    kill_at_ = t + kGraceTerm;
    return SIGTERM;
  }
  if (termed_ && !killed_ && t >= kill_at_) {
    killed_ = true;
    return SIGKILL;
  }
  return 0;
}

}  // namespace rths::supervisor
