#include "core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

namespace rths {

namespace {
constexpr auto kRedraw = std::chrono::milliseconds(250);
constexpr std::size_t kMaxWidth = 100;  ///< characters; longer lines are cut (no wrap on narrow terminals)
std::atomic<bool> g_turned_off{false};
}  // namespace

bool ProgressLine::StderrIsTerminal() { return ::isatty(2) == 1 && !g_turned_off; }

void ProgressLine::TurnOff() { g_turned_off = true; }

std::string ProgressLine::FormatSeconds(double s) {
  if (!(s >= 0.0) || !std::isfinite(s)) return "?";
  if (s < 9.95) return fmt::format("{:.1f} s", s);
  const long long t = std::llround(s);
  if (t < 60) return fmt::format("{} s", t);
  if (t < 3600) return fmt::format("{} min {:02d} s", t / 60, t % 60);
  return fmt::format("{} h {:02d} min", t / 3600, (t % 3600) / 60);
}

ProgressLine::ProgressLine(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled), start_(std::chrono::steady_clock::now()) {}

ProgressLine::~ProgressLine() { Finish(); }

void ProgressLine::Update(double done, double total, std::string_view detail) {
  if (!enabled_ || !(total > 0.0)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_draw_ < kRedraw && done < total) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double f = std::clamp(done / total, 0.0, 1.0);
  std::string eta = f > 0.0 && elapsed > 0.5 ? ", about " + FormatSeconds(elapsed * (1.0 - f) / f) + " left" : "";
  std::string line = fmt::format("{}  {:3.0f} %  {}{}", label_, 100.0 * f, FormatSeconds(elapsed), eta);
  if (!detail.empty()) line += fmt::format("  {}", detail);
  if (line.size() > kMaxWidth) line.resize(kMaxWidth);
  std::fprintf(stderr, "\r\033[K%s", line.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace rths
