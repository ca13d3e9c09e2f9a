// What `rths run` says of a run before and after it (supervisor/run_text.h).
#include "supervisor/run_text.h"

#include <fmt/format.h>

#include "core/exit_code.h"
#include "supervisor/disk.h"

namespace rths::supervisor {

std::string DefaultTransport(bool external, bool paced, const std::string& url, bool port_per_channel) {
  if (external) return "mixed";
  if (paced && url.empty() && !port_per_channel) return "memq";
  return "udpm";
}

std::string PlanHeader(const RunPlan& plan, const std::string& shown, const std::string& transport) {
  const auto& s = plan.scenario;
  std::string t = fmt::format("rths run: {} ({} steps of {:g} s), transport {}\n", shown, s.steps(), s.run.dt_s,
                              transport);
  // log.lcm's size is exact; a CSV row's length depends on the numbers (%.17g), so its size is
  // a bound (a 20 s default run: 6.5 MB written of 11.8 MB at most).
  const auto& z = plan.sizes;
  if (s.run.csv_every == 0) {
    t += fmt::format("  output           {}: log.lcm {}, no signals.csv (run.csv_every = 0, as --compact)\n",
                     Megabytes(z.total_bytes), Megabytes(z.log_bytes));
  } else {
    t += fmt::format("  output           at most {}: log.lcm {}, signals.csv up to {}{}\n", Megabytes(z.total_bytes),
                     Megabytes(z.log_bytes), Megabytes(z.csv_bytes),
                     s.run.csv_every == 1 ? " (--compact: none)" : fmt::format(" (every {} steps)", s.run.csv_every));
  }
  if (plan.url.rfind("udpm://", 0) == 0) t += fmt::format("  lcm url          {}\n", plan.url);
  return t;
}

std::string EndMessage(const RunSummary& sum, bool interrupted) {
  const std::string what = sum.failure ? sum.failure->what : "";
  if (interrupted) return "interrupted; the group was stopped";
  if (sum.exit_code == kExitSafety) return "STOPPED by the safety monitor: " + what;
  if (sum.exit_code == kExitPeerAbort) return "ABORTED: " + what;
  if (sum.exit_code == kExitRealtime) return "STOPPED by the real-time miss policy: " + what;
  return "FAILED: " + what;
}

}  // namespace rths::supervisor
