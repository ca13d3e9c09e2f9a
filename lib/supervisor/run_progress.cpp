#include "supervisor/run_progress.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "participants/factory.h"
#include "participants/logger.h"

namespace rths::supervisor {

namespace fs = std::filesystem;

RunProgress::RunProgress(const fs::path& log, const scenario::Scenario& s, bool enabled) : line_("rths run", enabled) {
  if (!line_.enabled() || s.steps() <= 0) return;
  const std::int64_t bytes_per_step = participants::LogBytesPerStepOf(s);
  thread_ = std::thread([this, log, steps = s.steps(), bytes_per_step] { Draw(log, steps, bytes_per_step); });
}

void RunProgress::Draw(const fs::path& log, std::int64_t steps, std::int64_t log_bytes_per_step) {
  std::unique_lock<std::mutex> lock(mutex_);
  bool drawn = false;
  while (!stop_) {
    std::error_code ec;
    const auto bytes = fs::file_size(log, ec);
    if (!ec) {
      drawn = true;
      const double done = std::min<double>(static_cast<double>(bytes) / static_cast<double>(log_bytes_per_step),
                                           static_cast<double>(steps));
      line_.Update(done, static_cast<double>(steps),
                   fmt::format("step {} of {}", static_cast<long long>(done), static_cast<long long>(steps)));
    }
    // Until log.lcm exists (the participants are starting), look again soon: a short run shows
    // its line too.
    cv_.wait_for(lock, std::chrono::milliseconds(drawn ? 250 : 20));
  }
}

RunProgress::~RunProgress() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  line_.Finish();
}

}  // namespace rths::supervisor
