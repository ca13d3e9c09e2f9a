#pragma once
/// @file Internal to lib/scenario: the schema of [safety], [lockstep], [realtime] and [faults], walked by the
/// visitors of fields.h (Reader, Writer, Checker): every key once, in file order, with its range.
#include "lockstep/config.h"
#include "lockstep/faults.h"
#include "lockstep/realtime.h"
#include "safety/monitor.h"
#include "scenario/ranges.h"

namespace rths::scenario::detail {

template <typename V>
void SafetyFields(V& v, safety::SafetyConfig& f, const Context&) {
  v.Bool("enabled", f.enabled);
  v.Number("stroke_mm", f.stroke_mm, OpenClosed(0.0, 10000.0));
  v.Number("force_kN", f.force_kN, OpenClosed(0.0, 1e6));
  v.Number("max_error_mm", f.max_error_mm, OpenClosed(0.0, 10000.0));
  v.Number("growth_window_s", f.growth_window_s, OpenClosed(0.0, 10.0));
  v.Number("growth_factor", f.growth_factor, OpenClosed(1.0, 1000.0));
  v.Integer("growth_windows", f.growth_windows, Closed(2, 1000));
  v.Number("growth_floor_mm", f.growth_floor_mm, OpenClosed(0.0, 10000.0));
}

template <typename V>
void LockstepFields(V& v, lockstep::LockstepConfig& l, const Context&) {
  v.Renamed("timeout_ms", "was renamed lockstep.rerequest_ms (re-request an incomplete step after this silence "
                          "[ms], [5, 10000]); the give-up time is lockstep.stall_budget_s");
  v.Renamed("max_attempts", "was replaced by lockstep.stall_budget_s: how long one step may stay incomplete "
                            "before the run stops [s], [1, 3600] (default 10)");
  // Below ~5 ms a re-request would come before a loaded 2-core host has even scheduled the
  // participants once: it only adds traffic.
  v.Number("rerequest_ms", l.rerequest_ms, Closed(5.0, 10000.0));
  v.Number("stall_budget_s", l.stall_budget_s,
           {std::max(1.0, 4e-3 * l.rerequest_ms), 3600.0, false, false, "at least 1 s and 4 lockstep.rerequest_ms"});
  v.Number("handshake_timeout_s", l.handshake_timeout_s, Closed(0.1, 600.0));
}

template <typename V>
void RealtimeFields(V& v, lockstep::RealtimeConfig& r, const Context&) {
  v.Bool("enabled", r.enabled);
  v.Integer("max_consecutive_misses", r.max_consecutive_misses, Closed(0.0, 1e9));
  v.Bool("sched_fifo", r.sched_fifo);
  v.Integer("priority", r.priority, Closed(1, 99));
  v.Bool("lock_memory", r.lock_memory);
  v.Number("spin_us", r.spin_us, Closed(0.0, 5000.0));
  v.Integer("cpu", r.cpu, Closed(-1, 1023));
}

template <typename V>
void FaultFields(V& v, lockstep::FaultConfig& f, const Context& cx) {
  for (auto [key, field] : {std::pair{"drop", &f.drop}, {"duplicate", &f.duplicate}, {"delay", &f.delay},
                            {"reorder", &f.reorder}}) {
    v.Number(key, *field, Closed(0.0, 0.5));
  }
  v.Number("delay_ms", f.delay_ms, OpenClosed(0.0, 10000.0));
  v.Integer("seed", f.seed, Closed(0.0, 9007199254740992.0));
  v.Integer("recv_buf_bytes", f.recv_buf_bytes);  // 0 or a range: ValidateFaults
  const bool present = !f.process_role.empty() || f.process_kind != lockstep::ProcessFault::kNone;
  v.Table(
      "process",
      [&](V& t) {
        t.String("role", f.process_role);
        t.Choice("kind", f.process_kind, lockstep::kProcessFaultNames);
        t.Integer("at_step", f.process_at_step,
                  {0.0, static_cast<double>(cx.steps), false, true, "a step of the run: [0, steps)"});
        t.Number("stop_s", f.process_stop_s, Closed(0.0, 3600.0));
      },
      present);
}

}  // namespace rths::scenario::detail
