#include "monitor/live_view.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rths::monitor {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Seconds(WallClock::time_point t) { return std::chrono::duration<double>(t.time_since_epoch()).count(); }

/// `*peak` becomes `v` if `v` is larger in magnitude (or `*peak` is NaN).
void KeepPeak(double v, double* peak) {
  if (std::isnan(*peak) || std::abs(v) > std::abs(*peak)) *peak = v;
}

LivePoint EmptyPoint() { return {0, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN}; }

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

LiveView::LiveView(LiveViewOptions options) : options_(options), slots_(kSlots), ring_(options.capacity) {
  status_.paced = options_.paced;
  open_ = EmptyPoint();
}

void LiveView::StartRun(std::int64_t run_id, std::int64_t n_steps, double dt_s) {
  status_ = LiveStatus{};
  status_.run_id = run_id;
  status_.paced = options_.paced;
  status_.phase = "starting";
  status_.n_steps = n_steps;
  SetStep(dt_s);
  std::fill(slots_.begin(), slots_.end(), Slot{});
  next_join_ = 0;
  open_ = EmptyPoint();
  open_count_ = 0;
  open_bucket_ = -1;
  made_ = 0;
  miss_run_ = 0;
  have_t0_ = false;
  rate_k_ = -1;
}

void LiveView::SetStep(double dt_s) {
  status_.dt_s = dt_s;
  bucket_steps_ = dt_s > 0 ? std::max<std::int64_t>(1, std::llround(1.0 / (dt_s * options_.points_per_sim_s))) : 1;
}

void LiveView::OnHandshake(std::int64_t run_id, int phase, const std::string& sender, std::int64_t n_steps,
                           double dt_s, const std::string& reason) {
  std::lock_guard lock(mutex_);
  constexpr int kRequest = 1, kGo = 3, kAbort = 4, kDone = 5, kClose = 7;
  if (run_id != status_.run_id) {
    if (phase == kAbort || phase == kClose) return;  // the end of a run we never saw start
    StartRun(run_id, n_steps, dt_s);
  }
  if (n_steps > 0 && status_.n_steps == 0) status_.n_steps = n_steps;
  if (dt_s > 0 && status_.dt_s == 0) SetStep(dt_s);
  if (status_.phase == "aborted" || status_.phase == "completed") return;
  switch (phase) {
    case kRequest: status_.phase = "starting"; break;
    case kGo: status_.phase = "running"; break;
    case kDone: Flush(); status_.phase = "finishing"; break;
    case kClose: Flush(); status_.phase = "completed"; break;
    case kAbort:
      Flush();
      status_.phase = "aborted";
      status_.abort_by = sender;
      status_.abort_reason = reason;
      break;
    default: break;
  }
}

LiveView::Slot& LiveView::SlotOf(std::int64_t k) {
  Slot& s = slots_[static_cast<std::size_t>(k) % kSlots];
  if (s.k != k) s = Slot{k};
  return s;
}

void LiveView::OnDesired(std::int64_t run_id, std::int64_t k, double r_mm, WallClock::time_point now) {
  std::lock_guard lock(mutex_);
  if (run_id != status_.run_id || k < next_join_) return;
  Slot& s = SlotOf(k);
  s.r = r_mm;
  s.has_r = true;
  s.released = now;
  if (status_.dt_s > 0) {
    const double t0 = Seconds(now) - static_cast<double>(k) * status_.dt_s;
    if (!have_t0_ || t0 < t0_s_) t0_s_ = t0;
    have_t0_ = true;
  }
}

void LiveView::OnCommand(std::int64_t run_id, std::int64_t k, double u_mm) {
  std::lock_guard lock(mutex_);
  if (run_id != status_.run_id || k < next_join_) return;
  Slot& s = SlotOf(k);
  s.u = u_mm;
  s.has_u = true;
}

void LiveView::OnMeasured(std::int64_t run_id, std::int64_t k, double y_mm, double f_kN, double i_A,
                          WallClock::time_point now) {
  std::lock_guard lock(mutex_);
  if (run_id != status_.run_id || k < next_join_) return;
  if (status_.phase == "starting") status_.phase = "running";  // GO lost: the steps say it
  Slot& s = SlotOf(k);
  if (s.has_y) return;  // a repaired (re-sent) message
  s.y = y_mm;
  s.f = f_kN;
  s.i = i_A;
  s.has_y = true;
  ++status_.steps_seen;
  status_.last_k = std::max(status_.last_k, k);
  if (status_.paced && status_.dt_s > 0) {
    s.latency_ms = s.has_r ? 1e3 * std::chrono::duration<double>(now - s.released).count() : kNaN;
    if (std::isfinite(s.latency_ms)) {
      status_.latency_ms = s.latency_ms;
      status_.latency_max_ms = std::max(status_.latency_max_ms, s.latency_ms);
    }
    const bool missed = have_t0_ && Seconds(now) > t0_s_ + static_cast<double>(k + 1) * status_.dt_s;
    miss_run_ = missed ? miss_run_ + 1 : 0;
    status_.misses += missed ? 1 : 0;
    status_.longest_miss_run = std::max(status_.longest_miss_run, miss_run_);
  }
  UpdateRate(now);
  // A monitor that joins late starts at the steps it hears.
  next_join_ = std::max(next_join_, k - static_cast<std::int64_t>(kSlots) + kJoinLag + 1);
  for (; next_join_ <= k - kJoinLag; ++next_join_) Join(next_join_);
}

void LiveView::Join(std::int64_t k) {
  const std::int64_t bucket = k / bucket_steps_;
  if (open_count_ > 0 && bucket != open_bucket_) CloseBucket();
  open_bucket_ = bucket;
  const Slot& s = slots_[static_cast<std::size_t>(k) % kSlots];
  if (s.k != k || !s.has_y) return;  // a lost measured_t: a gap
  open_.t_s = static_cast<double>(k) * status_.dt_s;
  if (s.has_r) KeepPeak(s.r, &open_.r_mm);
  if (s.has_u) KeepPeak(s.u, &open_.u_mm);
  KeepPeak(s.y, &open_.y_mm);
  if (s.has_r) KeepPeak(s.r - s.y, &open_.e_mm);
  KeepPeak(s.f, &open_.f_kN);
  KeepPeak(s.i, &open_.i_A);
  if (status_.paced) KeepPeak(s.latency_ms, &open_.latency_ms);
  ++open_count_;
  if ((k + 1) % bucket_steps_ == 0) CloseBucket();
}

void LiveView::CloseBucket() {
  if (open_count_ == 0) return;
  ring_[static_cast<std::size_t>(made_) % ring_.size()] = open_;
  ++made_;
  open_ = EmptyPoint();
  open_count_ = 0;
}

void LiveView::Flush() {
  for (; next_join_ <= status_.last_k; ++next_join_) Join(next_join_);
  CloseBucket();
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
      {"steps_seen", st.steps_seen},
      {"paced", st.paced},
      {"latency_ms", st.latency_ms},
      {"latency_max_ms", st.latency_max_ms},
      {"misses", st.misses},
      {"longest_miss_run", st.longest_miss_run},
  };
  const auto capacity = static_cast<std::int64_t>(ring_.size());
  std::int64_t from = std::clamp<std::int64_t>(cursor, std::max<std::int64_t>(0, made_ - capacity), made_);
  if (cursor > made_) from = std::max<std::int64_t>(0, made_ - capacity);  // a new run: start over
  const std::int64_t to = std::min<std::int64_t>(made_, from + static_cast<std::int64_t>(max_points));
  nlohmann::json points = nlohmann::json::array();
  for (std::int64_t n = from; n < to; ++n) {
    const LivePoint& p = ring_[static_cast<std::size_t>(n % capacity)];
    points.push_back({p.t_s, Number(p.r_mm), Number(p.u_mm), Number(p.y_mm), Number(p.e_mm), Number(p.f_kN),
                      Number(p.i_A), Number(p.latency_ms)});
  }
  return {{"status", status}, {"cursor", to}, {"points", points}};
}

}  // namespace rths::monitor
