#include "lockstep/live_feed.h"

#include <algorithm>
#include <cmath>

#include "lockstep/realtime.h"

namespace rths::lockstep {
namespace {

/// `*peak` becomes `v` if `v` is larger in magnitude, or if `first`.
void KeepPeak(double v, bool first, double* peak) {
  if (first || std::abs(v) > std::abs(*peak)) *peak = v;
}

}  // namespace

void LiveFeed::Start(std::int64_t run_id, std::int64_t n_steps, double dt_s, bool paced, const LiveLimits& limits) {
  record_ = rths::monitor_t{};
  record_.run_id = run_id;
  record_.phase = kLiveRunning;
  record_.k = -1;
  record_.n_steps = n_steps;
  record_.dt_s = dt_s;
  record_.paced = paced;
  record_.bucket_steps =
      dt_s > 0 ? static_cast<std::int32_t>(std::max<long long>(1, std::llround(1.0 / (dt_s * kLivePointsPerSimS))))
               : 1;
  record_.stroke_mm = limits.stroke_mm;
  record_.force_kN = limits.force_kN;
  record_.max_error_mm = limits.max_error_mm;
  ClearBucket();
}

void LiveFeed::ClearBucket() {
  in_bucket_ = 0;
  record_.r_mm = record_.u_mm = record_.y_mm = record_.e_mm = record_.f_kN = record_.current_A = 0;
  record_.latency_ms = 0;
  record_.bucket_misses = 0;
}

void LiveFeed::Add(std::int64_t k, double r_mm, double u_mm, double y_mm, double f_kN, double i_A, double latency_s,
                   bool missed, const RealtimeStats& rt, LiveSink* sink) {
  const bool first = in_bucket_ == 0;
  KeepPeak(r_mm, first, &record_.r_mm);
  KeepPeak(u_mm, first, &record_.u_mm);
  KeepPeak(y_mm, first, &record_.y_mm);
  KeepPeak(r_mm - y_mm, first, &record_.e_mm);
  KeepPeak(f_kN, first, &record_.f_kN);
  KeepPeak(i_A, first, &record_.current_A);
  record_.latency_ms = std::max(first ? 0.0 : record_.latency_ms, 1e3 * latency_s);
  record_.bucket_misses += missed ? 1 : 0;
  ++in_bucket_;
  record_.k = k;
  record_.steps = rt.steps;
  record_.misses = rt.misses;
  record_.longest_miss_run = rt.max_consecutive_misses;
  record_.latency_last_ms = 1e3 * latency_s;
  record_.latency_max_ms = 1e3 * rt.latency.max_s();
  record_.peak_disp_mm = std::max({record_.peak_disp_mm, std::abs(r_mm), std::abs(u_mm), std::abs(y_mm)});
  record_.peak_force_kN = std::max(record_.peak_force_kN, std::abs(f_kN));
  record_.peak_error_mm = std::max(record_.peak_error_mm, std::abs(r_mm - y_mm));
  if ((k + 1) % record_.bucket_steps == 0 || k + 1 == record_.n_steps) PushBucket(sink);
}

void LiveFeed::KeepActuatorPeaks(int n, const double* r_mm, const double* u_mm, const double* y_mm) {
  for (int i = 0; i < n; ++i) {
    record_.peak_disp_mm = std::max({record_.peak_disp_mm, std::abs(r_mm[i]), std::abs(u_mm[i]), std::abs(y_mm[i])});
    record_.peak_error_mm = std::max(record_.peak_error_mm, std::abs(r_mm[i] - y_mm[i]));
  }
}

void LiveFeed::PushBucket(LiveSink* sink) {
  if (in_bucket_ == 0) return;
  if (sink) sink->Push(record_);
  ClearBucket();
}

void LiveFeed::Phase(LivePhase phase, LiveSink* sink) {
  PushBucket(sink);
  record_.phase = phase;
  if (sink) sink->Push(record_);  // a record with no steps of its own: in_bucket_ 0, latency 0
}

}  // namespace rths::lockstep
