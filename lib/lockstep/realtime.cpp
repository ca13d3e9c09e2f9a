#include "lockstep/realtime.h"

#include <sched.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fmt/core.h>

namespace rths::lockstep {

void RealtimeStats::SizeWindows(std::int64_t n_steps, double period_s) {
  if (!(period_s > 0) || n_steps <= 0) return;
  window_steps = std::max<std::int64_t>(1, std::llround(kLatencyWindowS / period_s));
  const auto n = static_cast<std::size_t>((n_steps + window_steps - 1) / window_steps);
  window_max_s.assign(n, 0.0F);
  window_misses.assign(n, 0);
}

void LatencyHistogram::Add(double seconds) {
  int i = 0;
  if (seconds >= kLowestS) {
    const double decades = std::log10(seconds / kLowestS);
    i = 1 + static_cast<int>(std::floor(decades * kPerDecade));
    // log10 may round an exact edge down: make sure the value is not below the bin's lower edge.
    if (i < kBins - 1 && seconds >= LowerEdge(i + 1)) ++i;
    i = std::clamp(i, 1, kBins - 1);
  }
  ++bins_[i];
  ++count_;
  max_s_ = std::max(max_s_, seconds);
}

double LatencyHistogram::LowerEdge(int i) {
  if (i <= 0) return 0.0;
  return kLowestS * std::pow(10.0, static_cast<double>(i - 1) / kPerDecade);
}

double LatencyHistogram::UpperEdge(int i) {
  if (i >= kBins - 1) return INFINITY;
  return kLowestS * std::pow(10.0, static_cast<double>(i) / kPerDecade);
}

double LatencyHistogram::Quantile(double q) const {
  if (count_ == 0) return 0.0;
  // The smallest bin whose cumulative count reaches ceil(q n).
  const auto need = static_cast<std::int64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  std::int64_t seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += bins_[i];
    if (seen >= std::max<std::int64_t>(need, 1)) return std::min(UpperEdge(i), max_s_);
  }
  return max_s_;
}

RealtimeSetup EnterRealtime(bool fifo, int priority, bool lock, int cpu) {
  RealtimeSetup r;
  r.tried = true;
  std::string note;
  if (fifo) {
    sched_param p{};
    p.sched_priority = priority;
    if (::sched_setscheduler(0, SCHED_FIFO, &p) == 0) {
      r.fifo = true;
      r.priority = priority;
    } else {
      note += fmt::format("SCHED_FIFO priority {} not permitted ({}): needs CAP_SYS_NICE (root has it unless it was dropped) or an rtprio "
                          "limit (ulimit -r); running under the normal scheduler",
                          priority, std::strerror(errno));
    }
  }
  if (lock) {
    if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      r.memory_locked = true;
    } else {
      if (!note.empty()) note += "; ";
      note += fmt::format("mlockall not permitted ({}): needs CAP_IPC_LOCK (root has it unless it was dropped) or a memlock limit "
                          "(ulimit -l); memory may be paged",
                          std::strerror(errno));
    }
  }
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (cpu < CPU_SETSIZE && ::sched_setaffinity(0, sizeof set, &set) == 0) {
      r.cpu = cpu;
    } else {
      if (!note.empty()) note += "; ";
      note += fmt::format("cannot pin to CPU {} ({}): is it online and allowed (taskset -pc $$)?", cpu,
                          std::strerror(errno));
    }
  }
  r.note = note;
  return r;
}

}  // namespace rths::lockstep
