#include "monitor/live_view.h"

#include <algorithm>
#include <cmath>

#include "lockstep/live_feed.h"

namespace rths::monitor {
namespace {

constexpr int kRequest = 1, kGo = 3, kAbort = 4, kDone = 5, kClose = 7;  // lockstep/protocol.h

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

bool Ended(const LiveStatus& s) { return s.phase == "aborted" || s.phase == "completed"; }

}  // namespace

LiveView::LiveView(LiveViewOptions options) : options_(options), ring_(std::max<std::size_t>(1, options.capacity)) {}

void LiveView::StartRun(std::int64_t run_id, std::int64_t n_steps, double dt_s) {
  status_ = LiveStatus{};
  status_.run_id = run_id;
  status_.phase = "starting";
  status_.n_steps = n_steps;
  status_.dt_s = dt_s;
  made_ = 0;
  rate_k_ = -1;
}

void LiveView::OnHandshake(std::int64_t run_id, int phase, const std::string& sender, std::int64_t n_steps,
                           double dt_s, const std::string& reason) {
  std::lock_guard lock(mutex_);
  if (run_id != status_.run_id) {
    if (phase == kAbort || phase == kClose) return;  // the end of a run we never saw start
    StartRun(run_id, n_steps, dt_s);
  }
  if (n_steps > 0 && status_.n_steps == 0) status_.n_steps = n_steps;
  if (dt_s > 0 && status_.dt_s == 0) status_.dt_s = dt_s;
  if (phase == kAbort && status_.abort_by.empty() && status_.phase != "completed") {
    status_.phase = "aborted";  // the clock's record may have said so first, without the reason
    status_.abort_by = sender;
    status_.abort_reason = reason;
    return;
  }
  if (Ended(status_)) return;
  switch (phase) {
    case kRequest: status_.phase = "starting"; break;
    case kGo: status_.phase = "running"; break;
    case kDone: status_.phase = "finishing"; break;
    case kClose: status_.phase = "completed"; break;
    default: break;
  }
}

void LiveView::OnRecord(const rths::monitor_t& m, WallClock::time_point now) {
  std::lock_guard lock(mutex_);
  if (m.run_id != status_.run_id) StartRun(m.run_id, m.n_steps, m.dt_s);
  LiveStatus& s = status_;
  s.n_steps = m.n_steps;
  s.dt_s = m.dt_s;
  s.paced = m.paced;
  s.stroke_mm = m.stroke_mm;
  s.force_kN = m.force_kN;
  s.max_error_mm = m.max_error_mm;
  if (!Ended(s)) {
    switch (m.phase) {
      case lockstep::kLiveRunning: s.phase = "running"; break;
      case lockstep::kLiveFinishing: s.phase = "finishing"; break;
      case lockstep::kLiveCompleted: s.phase = "completed"; break;
      case lockstep::kLiveAborted: s.phase = "aborted"; break;
      default: break;
    }
  }
  if (m.k < 0 || m.k < s.last_k) return;  // before step 0, or an older record than one heard
  s.last_k = m.k;
  s.latency_ms = m.latency_last_ms;
  s.latency_max_ms = m.latency_max_ms;
  s.misses = m.misses;
  s.longest_miss_run = m.longest_miss_run;
  s.peak_disp_mm = m.peak_disp_mm;
  s.peak_force_kN = m.peak_force_kN;
  s.peak_error_mm = m.peak_error_mm;
  if (m.bucket_steps > 0) s.records_expected = (m.k + m.bucket_steps) / m.bucket_steps;
  UpdateRate(now);
  if (m.phase != lockstep::kLiveRunning) return;  // a phase record: no steps of its own
  ++s.records_heard;
  const LivePoint p{static_cast<double>(m.k) * m.dt_s, m.r_mm, m.u_mm, m.y_mm, m.e_mm, m.f_kN, m.current_A,
                    m.latency_ms, m.bucket_misses};
  ring_[static_cast<std::size_t>(made_) % ring_.size()] = p;
  ++made_;
}

void LiveView::OnEnd(std::int64_t run_id, const std::string& status, const std::string& by,
                     const std::string& reason, std::int64_t steps) {
  std::lock_guard lock(mutex_);
  if (run_id != status_.run_id) return;
  status_.phase = status == "completed" ? "completed" : "aborted";
  status_.last_k = steps - 1;
  status_.ended = true;
  if (status_.phase == "aborted" && status_.abort_by.empty()) {
    status_.abort_by = by;
    status_.abort_reason = reason;
  }
}

void LiveView::UpdateRate(WallClock::time_point now) {
  if (rate_k_ < 0) {
    rate_t_ = now;
    rate_k_ = status_.last_k;
    return;
  }
  const double span_s = std::chrono::duration<double>(now - rate_t_).count();
  if (span_s < 0.5) return;
  status_.steps_per_s = static_cast<double>(status_.last_k - rate_k_) / span_s;
  rate_t_ = now;
  rate_k_ = status_.last_k;
}

LiveStatus LiveView::Status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

std::int64_t LiveView::PointsMade() const {
  std::lock_guard lock(mutex_);
  return made_;
}

nlohmann::json LiveView::Since(std::int64_t cursor, std::size_t max_points) const {
  std::lock_guard lock(mutex_);
  const auto& st = status_;
  nlohmann::json status = {
      {"run_id", std::to_string(st.run_id)},  // 62 bits: a string, JavaScript's numbers hold 53
      {"phase", st.phase},
      {"abort_by", st.abort_by},
      {"abort_reason", st.abort_reason},
      {"n_steps", st.n_steps},
      {"dt_s", st.dt_s},
      {"last_k", st.last_k},
      {"steps_per_s", st.steps_per_s},
      {"records_heard", st.records_heard},
      {"records_expected", st.records_expected},
      {"paced", st.paced},
      {"ended", st.ended},
      {"latency_ms", st.latency_ms},
      {"latency_max_ms", st.latency_max_ms},
      {"misses", st.misses},
      {"longest_miss_run", st.longest_miss_run},
      {"limits", {{"stroke_mm", st.stroke_mm}, {"force_kN", st.force_kN}, {"max_error_mm", st.max_error_mm}}},
      {"peaks", {{"disp_mm", st.peak_disp_mm}, {"force_kN", st.peak_force_kN}, {"error_mm", st.peak_error_mm}}},
  };
  const auto capacity = static_cast<std::int64_t>(ring_.size());
  std::int64_t from = std::clamp<std::int64_t>(cursor, std::max<std::int64_t>(0, made_ - capacity), made_);
  if (cursor > made_) from = std::max<std::int64_t>(0, made_ - capacity);  // a new run: start over
  const std::int64_t to = std::min<std::int64_t>(made_, from + static_cast<std::int64_t>(max_points));
  nlohmann::json points = nlohmann::json::array();
  for (std::int64_t n = from; n < to; ++n) {
    const LivePoint& p = ring_[static_cast<std::size_t>(n % capacity)];
    points.push_back({p.t_s, Number(p.r_mm), Number(p.u_mm), Number(p.y_mm), Number(p.e_mm), Number(p.f_kN),
                      Number(p.i_A), Number(p.latency_ms), p.misses});
  }
  return {{"status", status}, {"cursor", to}, {"points", points}};
}

}  // namespace rths::monitor
