// libFuzzer target: the LCM event log reader (io::EventLogReader) and io::ReadRunLogBytes on
// arbitrary bytes, then what the tools compute from a log (ComputeMetrics, PayloadDigest,
// RigRecordFromRunLog) (docs/fuzzing.md). Property: rths::Error or a result, never a crash, a
// sanitizer finding or an allocation beyond -rss_limit_mb; a log it returns is consistent (events
// counted as the reader counts them, every step vector shorter than the number of events).
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "io/event_log.h"
#include "io/rig_record.h"
#include "io/run_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::int64_t events = -1;
  try {
    rths::io::EventLogReader reader("fuzz.lcm", data, size);
    rths::io::LogEvent ev;
    while (reader.Next(&ev)) {
      if (ev.channel.empty() || ev.channel.size() > rths::io::kMaxChannelBytes) std::abort();
      if (ev.offset_bytes + rths::io::EventBytes(ev.channel, ev.data.size()) > size) std::abort();
    }
    if (reader.truncated() && reader.truncated_at_byte() >= size) std::abort();
    events = reader.events();
  } catch (const rths::Error&) {
  }
  rths::io::RunLog log;
  try {
    log = rths::io::ReadRunLogBytes("fuzz.lcm", data, size);
  } catch (const rths::Error&) {
    return 0;
  }
  if (events < 0 || log.events != events) {
    std::fprintf(stderr, "ReadRunLogBytes read a log the reader refused or counted differently\n");
    std::abort();
  }
  for (std::size_t n : {log.desired.size(), log.command.size(), log.measured.size(), log.current.size()})
    if (static_cast<std::int64_t>(n) > log.events) std::abort();
  if (log.CompleteSteps() > log.events) std::abort();
  (void)rths::io::ComputeMetrics(log);
  (void)rths::io::PayloadDigest(log);
  (void)log.TruncationReason();
  try {
    (void)rths::io::RigRecordFromRunLog(log, "fuzz.lcm");
  } catch (const rths::Error&) {
  }
  return 0;
}
