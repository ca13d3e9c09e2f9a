#include "supervisor/summary_builder.h"

#include <fmt/format.h>

#include "core/exit_code.h"
#include "io/mapped_log_file.h"
#include "supervisor/realtime_figures.h"

namespace rths::supervisor {

RunSummary SummaryHead(const RunRequest& request, const RunPlan& plan) {
  RunSummary sum;
  sum.label = request.label;
  sum.scenario = plan.scenario_path;
  sum.scenario_sha256 = plan.scenario.sha256;
  sum.run_id = plan.run_id;
  sum.transport = request.transport;
  sum.steps_expected = plan.scenario.steps();
  if (!request.batch_summary) {
    sum.lcm_url = plan.url;
    sum.output_estimate_bytes = static_cast<std::int64_t>(plan.sizes.total_bytes);
  }
  return sum;
}

RunSummary BuildSummary(const RunRequest& request, const RunPlan& plan, const GroupEnd& end) {
  RunSummary sum = SummaryHead(request, plan);
  sum.wall_s = end.wall_s;
  // A logger killed before it could cut log.lcm back leaves the space it reserved as zero bytes:
  // cut them off, so the file ends on its last whole step (a log it cannot read stays as it is,
  // for ReadLog to report).
  try {
    io::TrimZeroTail((plan.out / "log.lcm").string());
  } catch (const std::exception&) {
  }
  ReadLog((plan.out / "log.lcm").string(), plan.scenario, &sum);  // + J1-J9 with a reference_file
  SetOutcomes(end.outcomes, &sum);
  SetVerdict(participants::Judge(end.outcomes), end.interrupted, &sum);
  if (sum.failure && end.noticed) {
    sum.failure->teardown_s = std::chrono::duration<double>(Clock::now() - *end.noticed).count();
  }
  if (plan.scenario.realtime.enabled) {
    sum.realtime = RealtimeFigures(plan.scenario, end.outcomes, request.transport, end.memq_setup);
  }
  if (request.batch_summary) {
    if (const std::string error = StudyError(sum); !error.empty()) MarkStudyFailure(error, &sum);
  }
  return sum;
}

std::string StudyError(const RunSummary& sum) {
  if (const auto* culprit = participants::RootCause(sum.participants)) {
    return fmt::format("{} exited with code {}: {}", culprit->role, culprit->exit_code, culprit->message);
  }
  if (!sum.log_error.empty()) return sum.log_error;
  if (sum.steps != sum.steps_expected) return fmt::format("the log holds {} of {} steps", sum.steps, sum.steps_expected);
  return "";
}

void MarkStudyFailure(const std::string& error, RunSummary* sum) {
  sum->stopped = error;
  if (sum->status == "completed") {
    sum->status = "failed";
    sum->exit_code = rths::kExitLockstep;
  }
}

}  // namespace rths::supervisor
