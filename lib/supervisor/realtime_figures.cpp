#include "supervisor/realtime_figures.h"

#include <fmt/core.h>

namespace rths::supervisor {

nlohmann::json RealtimeFigures(const scenario::Scenario& s, const std::vector<participants::Outcome>& outcomes,
                               const std::string& transport, const lockstep::RealtimeSetup& memq_setup) {
  nlohmann::json rt;
  for (const auto& o : outcomes) {
    if (const nlohmann::json r = o.RealtimeJson(); !r.is_null()) rt = r;
  }
  if (rt.is_null()) rt = nlohmann::json::object();
  int fifo = 0, locked = 0, processes = 0;
  std::string notes;
  auto count = [&](const lockstep::RealtimeSetup& r, const std::string& who) {
    if (!r.tried) return;
    ++processes;
    fifo += r.fifo;
    locked += r.memory_locked;
    if (!r.note.empty() && notes.find(r.note) == std::string::npos) notes += (notes.empty() ? "" : "; ") + who + ": " + r.note;
  };
  if (transport != "udpm") {
    count(memq_setup, fmt::format("rths run ({}: every built-in participant)", transport));
  } else {
    for (const auto& o : outcomes) count(o.realtime_setup, o.role);
  }
  rt["processes"] = processes;
  rt["sched_fifo_processes"] = fifo;
  rt["memory_locked_processes"] = locked;
  rt["priority"] = s.realtime.priority;
  rt["setup_notes"] = notes;
  rt["max_consecutive_misses_policy"] = s.realtime.max_consecutive_misses;
  return rt;
}

}  // namespace rths::supervisor
