#pragma once
/// @file The run's progress line: steps written (from the size of log.lcm) with an ETA.
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <thread>

#include "core/progress.h"
#include "scenario/scenario.h"

namespace rths::supervisor {

/// While it lives, redraws "rths run  37 %  ... step k of n" four times a second on stderr (if
/// `enabled`), counting the steps of `log` by its size.
class RunProgress {
 public:
  RunProgress(const std::filesystem::path& log, const scenario::Scenario& s, bool enabled);
  ~RunProgress();
  RunProgress(const RunProgress&) = delete;
  RunProgress& operator=(const RunProgress&) = delete;

 private:
  void Draw(const std::filesystem::path& log, std::int64_t steps, std::int64_t log_bytes_per_step);

  ProgressLine line_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
};

}  // namespace rths::supervisor
