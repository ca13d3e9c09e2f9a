#include "supervisor/run.h"

#include <chrono>

#include <fmt/format.h>

#include "core/names.h"
#include "io/output_folder.h"
#include "io/reserved_file.h"
#include "lockstep/abort.h"
#include "core/exit_code.h"
#include "lockstep/faults.h"
#include "lockstep/protocol.h"
#include "lockstep/step_table.h"
#include "lockstep/transport.h"
#include "participants/factory.h"
#include "supervisor/in_process_group.h"
#include "supervisor/ports.h"
#include "supervisor/process_group.h"
#include "supervisor/run_progress.h"
#include "supervisor/scenario_file.h"
#include "supervisor/summary_builder.h"
#include "supervisor/teardown.h"

namespace rths::supervisor {

namespace fs = std::filesystem;

namespace {

/// The user's --lcm-url, with port_per_channel=1 if --port-per-channel asks for it (RunRequest::IsValid
/// checked the URL).
std::string UserUrl(const RunRequest& r) {
  if (!r.port_per_channel || lockstep::IsPortPerChannel(r.lcm_url)) return r.lcm_url;
  auto parsed = lockstep::UdpmUrl::Parse(r.lcm_url);
  if (!parsed) throw Error("--lcm-url", r.lcm_url + ": not a udpm URL");
  parsed->port_per_channel = true;
  return parsed->ToString();
}

/// A udpm run's URL: the user's, or the multicast group on a free port (a port per channel if
/// asked), with the scenario's receive buffer size.
std::string UdpmUrl(const RunRequest& r) {
  if (const std::string hint = participants::MulticastRouteAdvice(); !hint.empty()) throw Error("", hint);
  std::string url = !r.lcm_url.empty()     ? UserUrl(r)
                    : r.port_per_channel ? fmt::format("udpm://239.255.76.67:{}?ttl=0&port_per_channel=1",
                                                       FreeUdpPorts(static_cast<int>(lockstep::kPortChannels.size())))
                                         : fmt::format("udpm://239.255.76.67:{}?ttl=0", FreeUdpPort());
  if (const auto bytes = r.scenario.faults.recv_buf_bytes; bytes > 0) {
    url += fmt::format("{}recv_buf_size={}", url.find('?') == std::string::npos ? "?" : "&", bytes);
  }
  return url;
}

/// Everything that can be checked before a byte is written (unless the caller did).
RunPlan Plan(const RunRequest& r) {
  RunPlan plan;
  plan.scenario = r.scenario;
  plan.scenario_path = r.scenario_path;
  plan.url = "memq://";
  plan.run_id = r.run_id > 0 ? r.run_id : lockstep::NewRunId();
  plan.out = r.out;
  if (std::string why; !r.IsValid(&why)) throw Error("", why);
  if (!r.check_before_start) {
    if (r.transport != "memq") plan.url = UdpmUrl(r);
    return plan;
  }
  const scenario::Scenario& s = r.scenario;
  participants::CheckBuildable(s);
  if (r.transport != "udpm" && lockstep::EndsProcess(s.faults.process_kind) &&
      !r.external.has(s.faults.process_role)) {
    throw Error(r.scenario_path + ": faults.process.kind",
                fmt::format("\"{}\" would take every participant down with the one {} process: use --transport udpm",
                            NameOf(lockstep::kProcessFaultNames, s.faults.process_kind), r.transport));
  }
  if (r.transport != "memq") plan.url = UdpmUrl(r);
  if (plan.out.empty()) plan.out = io::NewOutputFolder(s.run.name);
  io::RequireNewOrEmptyFolder(plan.out, "a previous run");
  plan.sizes = EstimateOutput(s);
  if (r.check_disk_space) CheckDiskSpace(plan.out, s, plan.sizes);
  if (plan.sizes.total_bytes > kWarnBytes && r.on_warning) {
    r.on_warning(fmt::format("this run will write about {} to {}", Megabytes(plan.sizes.total_bytes), plan.out.string()));
  }
  return plan;
}

/// The output folder with the scenario that runs and the reserved summary. If that fails, what
/// was made here is removed, so a retry with the same folder works.
void PrepareFolder(const RunRequest& r, RunPlan* plan) {
  plan->created_out = !fs::exists(plan->out);
  const fs::path file = plan->out / "scenario.toml";
  try {
    fs::create_directories(plan->out);
    if (r.scenario_header.empty()) {
      fs::copy_file(r.scenario_path, file);
    } else {
      plan->scenario_path = file.string();
      plan->scenario = WriteScenarioFile(file, r.scenario_header, plan->scenario);
    }
    const fs::path summary = plan->out / r.summary_file;
    if (!r.summary_file.empty() && !io::ReserveFile(summary.string(), kSummaryReserve, "{\"status\": \"running\"}\n")) {
      throw Error(summary.string(), "cannot reserve the summary (disk full?)");
    }
  } catch (const std::exception& e) {
    std::error_code ec;
    if (plan->created_out && !r.keep_folder) fs::remove_all(plan->out, ec);
    throw RunError(rths::kExitUsage, e.what(), SummaryHead(r, *plan));
  }
}

/// Runs the group (processes or in this process) and says how it ended. If it cannot run, the
/// folder made for it is removed unless it holds a log.
GroupEnd RunGroup(const RunRequest& r, const RunPlan& plan) {
  GroupEnd end;
  volatile std::sig_atomic_t not_interruptible = 0;
  volatile std::sig_atomic_t* interrupted = r.interrupted ? r.interrupted : &not_interruptible;
  const auto t0 = Clock::now();
  bool group_started = false;  // an on_start that throws (a monitor that cannot bind): nothing ran
  try {
    if (r.on_start) r.on_start(plan);
    group_started = true;
    const RunProgress progress(plan.out / "log.lcm", plan.scenario, r.progress);
    if (r.transport == "memq" || r.transport == "mixed") {
      end.outcomes = RunInProcessGroup(plan.scenario, r.replay ? &*r.replay : nullptr, &r.external, plan.url,
                                       plan.run_id, plan.out.string(), interrupted, &end.memq_setup, r.live_sink);
      // The built-in participants stopped at the interrupt; the external ones hear it here.
      if (r.transport == "mixed" && *interrupted) {
        lockstep::BroadcastAbort(plan.url, plan.run_id, "supervisor", "interrupted by the user");
      }
    } else {
      const ProcessGroupSpec spec{plan.scenario_path, plan.run_id, plan.out,   r.bin_dir,
                                  plan.url,           r.external,  r.role_args};
      Clock::time_point noticed{};
      end.outcomes = RunProcessGroup(spec, interrupted, &noticed);
      if (noticed != Clock::time_point{}) end.noticed = noticed;
    }
  } catch (const std::exception& e) {
    std::error_code ec;
    if (plan.created_out && !r.keep_folder && !fs::exists(plan.out / "log.lcm")) fs::remove_all(plan.out, ec);
    RunSummary head = SummaryHead(r, plan);
    head.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
    throw RunError(group_started ? rths::kExitLockstep : rths::kExitUsage, e.what(), head);
  }
  end.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  end.interrupted = *interrupted != 0;
  // The user's participants, as the clock saw them.
  const participants::Outcome* clock = nullptr;
  for (const auto& o : end.outcomes) {
    if (o.role == lockstep::kClockRole) clock = &o;
  }
  std::vector<participants::Outcome> external;
  for (const auto& role : r.external.roles) external.push_back(participants::ExternalOutcome(role, clock));
  end.outcomes.insert(end.outcomes.end(), external.begin(), external.end());
  return end;
}

}  // namespace

RunResult Run(const RunRequest& request) {
  RunResult result;
  try {
    result.plan = Plan(request);
  } catch (const std::exception& e) {
    throw RunError(rths::kExitUsage, e.what(), {});
  }
  PrepareFolder(request, &result.plan);
  const GroupEnd end = RunGroup(request, result.plan);
  result.summary = BuildSummary(request, result.plan, end);
  if (!request.summary_file.empty()) {
    result.summary_written = io::OverwriteFile((result.plan.out / request.summary_file).string(),
                                               result.summary.ToJson().dump(2) + "\n");
  }
  return result;
}

}  // namespace rths::supervisor
