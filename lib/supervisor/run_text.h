#pragma once
/// @file What `rths run` says of a run before and after it, and the default transport
/// (docs/realtime.md, "Which transport"): the supervisor's words, printed by the tool.
#include <string>

#include "supervisor/request.h"

namespace rths::supervisor {

/// The transport of a run whose command line names none: mixed with --external; memq for a paced
/// run that names no udpm option (`url` empty, no port per channel: it holds the pace best, the
/// step a function call, not five processes' datagrams); else udpm.
std::string DefaultTransport(bool external, bool paced, const std::string& url, bool port_per_channel);

/// The lines before a run: "rths run: SHOWN (N steps of dt s), transport T", the output it will
/// write (log.lcm exact, signals.csv a bound) and, for udpm, its LCM URL; each ends in '\n'.
/// `shown` is the scenario as the user named it (with the overrides).
std::string PlanHeader(const RunPlan& plan, const std::string& shown, const std::string& transport);

/// One line (no "rths run: ", no '\n') for a run that did not end with exit 0: interrupted;
/// "STOPPED by the safety monitor: ..."; "ABORTED: ..."; "STOPPED by the real-time miss policy:
/// ..."; else "FAILED: ..." with the failure's text.
std::string EndMessage(const RunSummary& sum, bool interrupted);

}  // namespace rths::supervisor
