#pragma once
/// @file A one-line progress display for long jobs (runs, sweeps, fits, the diagnosis): on a
/// terminal, "label  37 %  12.0 s, about 20 s left  detail" redrawn in place on stderr at most four
/// times a second; when stderr is not a terminal (a pipe, a file, CI) it prints nothing at all, so
/// logs and test output stay as they were. Thread-safe: batch workers may report concurrently.
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

namespace rths {

/// How a long computation reports how far it is: `done` of `total` units of work and what it is
/// doing. Libraries take one in their options (empty: nobody listens); a main program passes
/// ProgressLine::Update.
using ProgressFn = std::function<void(double done, double total, std::string_view what)>;

class ProgressLine {
 public:
  /// `enabled`: draw at all; by default, only if stderr is a terminal (isatty(2)) and the main
  /// program has not turned progress lines off (TurnOff). Main programs decide; libraries take a
  /// ProgressLine* that may be null.
  explicit ProgressLine(std::string label, bool enabled = StderrIsTerminal());
  ~ProgressLine();  ///< clears the line (Finish())
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// Reports `done` of `total` units (total > 0); the ETA is elapsed x (total - done) / done.
  void Update(double done, double total, std::string_view detail = {});
  /// Clears the line (idempotent); later output starts on a clean line.
  void Finish();
  bool enabled() const { return enabled_; }

  /// True if stderr is a terminal and progress lines were not turned off.
  static bool StderrIsTerminal();
  /// Turns every later progress line of this process off: a main program's answer to the user
  /// (tools/cli.h: the environment sets RTHS_NO_PROGRESS). Libraries never call it.
  static void TurnOff();
  /// "12 s", "3 min 05 s", "1 h 02 min".
  static std::string FormatSeconds(double s);

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
  std::mutex mutex_;
};

}  // namespace rths
