#include "io/run_log.h"

#include <algorithm>
#include <cmath>
#include <lcm/lcm-cpp.hpp>

#include "core/error.h"
#include "lockstep/runtime.h"
#include "scenario/scenario.h"
#include "signal/metrics.h"

namespace rths::io {

namespace {
template <class Msg>
void Store(const lcm::LogEvent* ev, const std::string& path, std::vector<Msg>* by_k, RunLog* log) {
  Msg m;
  if (m.decode(ev->data, 0, ev->datalen) < 0) {
    throw Error(path, "event " + std::to_string(ev->eventnum) + " on " + ev->channel +
                          " cannot be decoded");
  }
  if (m.k < 0) throw Error(path, "negative step index on " + ev->channel);
  const auto k = static_cast<std::size_t>(m.k);
  if (by_k->size() <= k) by_k->resize(k + 1, [] { Msg e{}; e.k = -1; return e; }());
  auto& raw = log->payload[ev->channel];
  if (raw.size() <= k) raw.resize(k + 1);
  ++log->count[ev->channel];
  if ((*by_k)[k].k == m.k) {
    ++log->duplicates[ev->channel];
    return;
  }
  (*by_k)[k] = m;
  m.run_id = 0;  // differs between runs by design; everything else must not
  lockstep::Encode(m, &raw[k]);
}
}  // namespace

std::int64_t RunLog::CompleteSteps() const {
  const std::size_t n = std::min({desired.size(), command.size(), measured.size(), current.size()});
  std::size_t k = 0;
  while (k < n && desired[k].k >= 0 && command[k].k >= 0 && measured[k].k >= 0 && current[k].k >= 0) {
    ++k;
  }
  return static_cast<std::int64_t>(k);
}

std::string RunLog::AbortReason() const {
  for (const auto& h : handshakes) {
    if (h.phase == lockstep::kAbort) return h.participant + ": " + h.reason;
  }
  return "";
}

RunLog ReadRunLog(const std::string& path) {
  lcm::LogFile file(path, "r");
  if (!file.good()) throw Error(path, "cannot open the LCM event log");
  RunLog log;
  for (const lcm::LogEvent* ev = file.readNextEvent(); ev; ev = file.readNextEvent()) {
    if (ev->channel == lockstep::kChDesired) {
      Store(ev, path, &log.desired, &log);
      if (log.first_desired_utime == 0) log.first_desired_utime = ev->timestamp;
      log.last_desired_utime = ev->timestamp;
    } else if (ev->channel == lockstep::kChCommand) {
      Store(ev, path, &log.command, &log);
    } else if (ev->channel == lockstep::kChMeasured) {
      Store(ev, path, &log.measured, &log);
    } else if (ev->channel == lockstep::kChCurrent) {
      Store(ev, path, &log.current, &log);
    } else if (ev->channel == lockstep::kChHandshake) {
      rths::handshake_t h;
      if (h.decode(ev->data, 0, ev->datalen) < 0) throw Error(path, "bad handshake event");
      log.run_id = h.run_id;
      log.handshakes.push_back(h);
    } else {
      ++log.unknown_events;
    }
  }
  return log;
}

RunMetrics ComputeMetrics(const RunLog& log) {
  RunMetrics m;
  m.steps = log.CompleteSteps();
  const auto n = static_cast<std::size_t>(m.steps);
  std::vector<double> r(n), y(n), acc_pred, acc_true, vel_pred, vel_true;
  for (std::size_t k = 0; k < n; ++k) {
    r[k] = log.desired[k].r_mm;
    y[k] = log.measured[k].y_mm;
    m.peak_force_kN = std::max(m.peak_force_kN, std::abs(log.measured[k].f_kN));
    m.peak_displacement_mm = std::max(m.peak_displacement_mm, std::abs(y[k]));
    if (k >= 2 && k + 1 < n) {  // from k = 2 the extrapolation has a real history
      acc_pred.push_back(log.desired[k].rdd_mm_s2);
      acc_true.push_back(log.desired[k + 1].acc_prev_mm_s2);
      vel_pred.push_back(log.desired[k].rd_mm_s);
      vel_true.push_back(log.desired[k + 1].vel_prev_mm_s);
    }
  }
  // Eq. 31's norm; 0 where the reference is all zeros (nothing to compare).
  auto pct = [](const std::vector<double>& reference, const std::vector<double>& estimate) {
    const double p = signal::RmsErrorPercent(reference, estimate);
    return std::isfinite(p) ? p : 0.0;
  };
  m.tracking_nrmse_pct = pct(r, y);
  m.accel_extrapolation_rms_err_pct = pct(acc_true, acc_pred);
  m.velocity_prediction_rms_err_pct = pct(vel_true, vel_pred);
  const double span_s = (log.last_desired_utime - log.first_desired_utime) * 1e-6;
  m.steps_per_s = (m.steps > 1 && span_s > 0) ? (m.steps - 1) / span_s : 0.0;
  return m;
}

std::string PayloadDigest(const RunLog& log) {
  std::string all;
  for (const auto& [channel, per_k] : log.payload) {  // std::map: sorted by channel name
    all += channel;
    all.push_back('\0');
    for (const auto& bytes : per_k) {
      const std::uint64_t n = bytes.size();
      all.append(reinterpret_cast<const char*>(&n), sizeof n);
      all.append(bytes.begin(), bytes.end());
    }
  }
  return scenario::Sha256Hex(all);
}

}  // namespace rths::io
