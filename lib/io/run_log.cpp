#include "io/run_log.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include <fmt/format.h>

#include "core/error.h"
#include "io/event_log.h"
#include "lockstep/protocol.h"
#include "scenario/scenario.h"
#include "signal/metrics.h"

namespace rths::io {

namespace {

/// Field kinds of the LCM wire format, to check a payload's shape before lcm-gen's decode()
/// trusts it: decode() resizes arrays to the count in the payload before checking that the
/// elements are there (a count of 2^31-1 asks for 16 GB) and takes string lengths < 1 as huge.
enum class Wire { kI8, kI32, kI64, kF64, kString, kCount, kF64Array, kStringArray };

/// What is wrong with `d` as the encoding of a message with fingerprint `hash` and fields `layout`
/// (kCount gives the length of the arrays after it), or "" if nothing: too short, another type's
/// fingerprint, a string length outside [1, bytes left] or a string without its NUL, an array
/// count outside [0, what the bytes left can hold], bytes left over after the message.
std::string WireProblem(const std::vector<std::uint8_t>& d, std::int64_t hash, const std::vector<Wire>& layout) {
  const std::size_t n = d.size();
  std::size_t pos = 0;
  auto left = [&] { return n - pos; };
  auto get = [&](int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | d[pos + i];
    pos += bytes;
    return v;
  };
  if (left() < 8) return fmt::format("{} bytes are too short for a message (8-byte type fingerprint)", n);
  const auto h = static_cast<std::int64_t>(get(8));
  if (h != hash) {
    return fmt::format("type fingerprint 0x{:016x} is not the channel's type (0x{:016x})", static_cast<std::uint64_t>(h),
                       static_cast<std::uint64_t>(hash));
  }
  std::int64_t count = 0;
  auto string = [&]() -> std::string {
    if (left() < 4) return "the message ends inside a string length";
    const auto len = static_cast<std::int32_t>(get(4));
    if (len < 1 || static_cast<std::uint64_t>(len) > left())
      return fmt::format("string length {} is out of range [1, {}] (the bytes left)", len, left());
    if (d[pos + static_cast<std::size_t>(len) - 1] != 0) return "a string lacks its terminating NUL";
    pos += static_cast<std::size_t>(len);
    return "";
  };
  for (Wire w : layout) {
    switch (w) {
      case Wire::kI8:
      case Wire::kI32:
      case Wire::kI64:
      case Wire::kF64: {
        const std::size_t bytes = w == Wire::kI8 ? 1 : w == Wire::kI32 ? 4 : 8;
        if (left() < bytes) return fmt::format("the message ends inside a field ({} bytes)", n);
        pos += bytes;
        break;
      }
      case Wire::kCount:
        if (left() < 4) return fmt::format("the message ends inside an array length ({} bytes)", n);
        count = static_cast<std::int32_t>(get(4));
        if (count < 0 || static_cast<std::uint64_t>(count) > left())
          return fmt::format("array length {} is out of range [0, {}] (the bytes left)", count, left());
        break;
      case Wire::kF64Array:
        if (static_cast<std::uint64_t>(count) * 8 > left())
          return fmt::format("an array of {} numbers does not fit in the {} bytes left", count, left());
        pos += static_cast<std::size_t>(count) * 8;
        break;
      case Wire::kStringArray:
        for (std::int64_t i = 0; i < count; ++i)
          if (auto p = string(); !p.empty()) return p;
        break;
      case Wire::kString:
        if (auto p = string(); !p.empty()) return p;
        break;
    }
  }
  if (pos != n) return fmt::format("{} bytes left over after the message", n - pos);
  return "";
}

// The layouts of lcmtypes/*.lcm, field by field (the tests read real logs through them, so a
// layout that no longer matches its type is caught at once).
using enum Wire;
const std::vector<Wire> kHandshakeLayout = {kI64, kI8,    kString,      kString,      kI64, kF64,
                                                      kI64, kCount, kStringArray, kStringArray, kString,
                                                      kI32, kF64};
const std::vector<Wire> kDesiredLayout = {kI64, kI64, kF64,      kF64,      kF64,   kF64,     kF64, kF64,
                                          kF64, kCount, kF64Array, kF64Array, kCount, kF64Array};
const std::vector<Wire> kCommandLayout = {kI64, kI64, kF64, kF64, kF64, kCount, kF64Array, kCount, kF64Array};
const std::vector<Wire> kMeasuredLayout = {kI64, kI64, kF64, kF64, kF64, kCount, kF64Array, kCount, kF64Array};
const std::vector<Wire> kCurrentLayout = {kI64, kI64, kF64, kF64};

/// Decodes `ev` as a Msg after checking its shape; throws "<source>: byte N: ..." if it is not one.
template <class Msg>
Msg Decode(const LogEvent& ev, const std::vector<Wire>& layout, const std::string& source) {
  Msg m;
  std::string problem = WireProblem(ev.data, Msg::getHash(), layout);
  if (problem.empty() && m.decode(ev.data.data(), 0, static_cast<int>(ev.data.size())) !=
                             static_cast<int>(ev.data.size()))
    problem = "lcm decode() refused it";
  if (!problem.empty()) {
    throw Error(source, fmt::format("byte {}: event {} on {}: the payload is not a {} ({})", ev.offset_bytes,
                                    ev.event_number, ev.channel, Msg::getTypeName(), problem));
  }
  return m;
}

/// The messages of one step channel in file order, with where each came from.
template <class Msg>
struct StepEvents {
  const char* channel;
  std::vector<Msg> msgs;
  std::vector<std::uint64_t> offsets;
};

/// Files the messages by k (a missing step has k = -1), counting repeats of a (channel, k).
template <class Msg>
void Place(const StepEvents<Msg>& in, std::vector<Msg>* by_k, RunLog* log) {
  auto& raw = log->payload[in.channel];
  auto& count = log->count[in.channel];
  for (const Msg& m0 : in.msgs) {
    const auto k = static_cast<std::size_t>(m0.k);
    if (by_k->size() <= k) by_k->resize(k + 1, [] { Msg e{}; e.k = -1; return e; }());
    if (raw.size() <= k) raw.resize(k + 1);
    ++count;
    if ((*by_k)[k].k == m0.k) {
      ++log->duplicates[in.channel];
      continue;
    }
    (*by_k)[k] = m0;
    Msg m = m0;
    m.run_id = 0;  // differs between runs by design; everything else must not
    lockstep::Encode(m, &raw[k]);
  }
}

/// The first message whose k cannot belong to the log: k < 0 or k >= bound. Returns its offset
/// (or UINT64_MAX) and puts its k in *bad_k.
template <class Msg>
std::uint64_t FirstBadStep(const StepEvents<Msg>& in, std::int64_t bound, std::int64_t* bad_k) {
  for (std::size_t i = 0; i < in.msgs.size(); ++i) {
    if (in.msgs[i].k < 0 || in.msgs[i].k >= bound) {
      *bad_k = in.msgs[i].k;
      return in.offsets[i];
    }
  }
  return UINT64_MAX;
}

RunLog Read(EventLogReader& reader) {
  const std::string& source = reader.name();
  RunLog log;
  log.source = source;
  log.file_bytes = reader.size_bytes();
  StepEvents<rths::desired_t> desired{lockstep::kChDesired, {}, {}};
  StepEvents<rths::command_t> command{lockstep::kChCommand, {}, {}};
  StepEvents<rths::measured_t> measured{lockstep::kChMeasured, {}, {}};
  StepEvents<rths::current_t> current{lockstep::kChCurrent, {}, {}};
  bool first_desired = true;
  LogEvent ev;
  auto keep = [&](auto& events, const std::vector<Wire>& layout) {
    using Msg = typename std::decay_t<decltype(events.msgs)>::value_type;
    events.msgs.push_back(Decode<Msg>(ev, layout, source));
    events.offsets.push_back(ev.offset_bytes);
  };
  while (reader.Next(&ev)) {
    if (ev.channel == lockstep::kChDesired) {
      keep(desired, kDesiredLayout);
      if (first_desired) log.first_desired_utime = ev.utime;
      first_desired = false;
      log.last_desired_utime = ev.utime;
    } else if (ev.channel == lockstep::kChCommand) {
      keep(command, kCommandLayout);
    } else if (ev.channel == lockstep::kChMeasured) {
      keep(measured, kMeasuredLayout);
    } else if (ev.channel == lockstep::kChCurrent) {
      keep(current, kCurrentLayout);
    } else if (ev.channel == lockstep::kChHandshake) {
      const auto h = Decode<rths::handshake_t>(ev, kHandshakeLayout, source);
      log.run_id = h.run_id;
      log.n_steps = std::max(log.n_steps, h.n_steps);
      if (h.phase == lockstep::kDone) log.done = true;
      log.handshakes.push_back(h);
    } else {
      ++log.unknown_events;
    }
  }
  log.events = reader.events();
  log.truncated_tail = reader.truncated();
  log.truncated_at_byte = reader.truncated_at_byte();
  log.zero_tail = reader.zero_tail();
  log.zero_tail_at_byte = reader.zero_tail_at_byte();

  // Every k must be able to belong to this log: below the planned steps and below the number of
  // events (a step has a message on each channel). This also bounds the vectors below.
  const std::int64_t bound = log.n_steps > 0 ? std::min(log.n_steps, log.events) : log.events;
  std::int64_t bad_k = 0, k = 0;
  std::uint64_t at = UINT64_MAX, o = 0;
  const char* channel = "";
  auto check = [&](const auto& events) {
    if ((o = FirstBadStep(events, bound, &k)) < at) at = o, bad_k = k, channel = events.channel;
  };
  check(desired);
  check(command);
  check(measured);
  check(current);
  if (at != UINT64_MAX) {
    const std::string why =
        bad_k < 0 ? "a step index is never negative"
                  : (log.n_steps > 0 && log.n_steps <= log.events
                         ? fmt::format("the handshake plans {} steps: k in [0, {}]", log.n_steps, log.n_steps - 1)
                         : fmt::format("the file holds only {} events", log.events));
    throw Error(source, fmt::format("byte {}: {} message with step index k = {} cannot belong to this log ({})", at,
                                    channel, bad_k, why));
  }
  Place(desired, &log.desired, &log);
  Place(command, &log.command, &log);
  Place(measured, &log.measured, &log);
  Place(current, &log.current, &log);
  return log;
}

}  // namespace

std::filesystem::path RunFolderLog(const std::filesystem::path& run_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(run_dir, ec);
  if (!fs::exists(st)) {
    throw Error(run_dir.string(), "no such run folder (give the folder `rths run` printed, e.g. runs/<time>-<name>)");
  }
  if (!fs::is_directory(st)) {
    const fs::path parent = run_dir.has_parent_path() ? run_dir.parent_path() : fs::path(".");
    throw Error(run_dir.string(), fmt::format("is a file, not a run folder: give the folder that holds log.lcm{}",
                                              run_dir.filename() == "log.lcm" ? " (here " + parent.string() + ")" : ""));
  }
  const fs::path log = run_dir / "log.lcm";
  if (!fs::is_regular_file(log, ec)) {
    throw Error(run_dir.string(), "no log.lcm in this folder (a run folder of `rths run` holds log.lcm, scenario.toml, "
                                  "summary.json)");
  }
  return log;
}

std::string RunLog::ScenarioSha256() const {
  for (const auto& h : handshakes)
    if (!h.scenario_sha256.empty()) return h.scenario_sha256;
  return "";
}

double RunLog::StepS() const {
  for (const auto& h : handshakes) {
    if (h.dt_s > 0.0 && std::isfinite(h.dt_s)) return h.dt_s;
  }
  return 0.0;
}

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

std::string RunLog::TruncationReason() const {
  std::string r;
  if (!done) r = "truncated (the run did not finish: no DONE handshake)";
  if (truncated_tail) {
    r += fmt::format("{}the file ends in the middle of an event at byte {} (of {})", r.empty() ? "" : "; ",
                     truncated_at_byte, file_bytes);
  }
  return r;
}

RunLog ReadRunLog(const std::string& path) {
  EventLogReader reader(path);
  return Read(reader);
}

RunLog ReadRunLogBytes(const std::string& name, const std::uint8_t* bytes, std::size_t size_bytes) {
  EventLogReader reader(name, bytes, size_bytes);
  return Read(reader);
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
  // In double: the timestamps are whatever the file says (an int64 difference can overflow;
  // found by fuzz_event_log).
  const double span_s =
      (static_cast<double>(log.last_desired_utime) - static_cast<double>(log.first_desired_utime)) * 1e-6;
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
