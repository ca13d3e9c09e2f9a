#include "supervisor/run_summary.h"

#include <algorithm>
#include <exception>

#include <fmt/format.h>

#include "participants/benchmark_run.h"

namespace rths::supervisor {

using participants::BenchmarkCriteriaOfRun;
using participants::Judge;
using participants::StatsToJson;

double RunSummary::steps_per_s() const {
  return (steps > 1 && stepping_s > 0) ? static_cast<double>(steps - 1) / stepping_s : 0.0;
}

nlohmann::json RunSummary::ToJson() const {
  nlohmann::json j;
  if (!label.empty()) j["label"] = label;
  j["scenario"] = scenario;
  j["scenario_sha256"] = scenario_sha256;
  j["run_id"] = run_id;
  j["transport"] = transport;
  if (!lcm_url.empty()) j["lcm_url"] = lcm_url;
  j["steps_expected"] = steps_expected;
  j["wall_s"] = wall_s;
  if (output_estimate_bytes > 0) j["output_estimate_bytes"] = output_estimate_bytes;
  j["steps"] = steps;
  if (metrics) {
    j["stepping_s"] = stepping_s;
    j["steps_per_s"] = steps_per_s();
    j["tracking_nrmse_pct"] = metrics->tracking_nrmse_pct;
    j["peak_force_kN"] = metrics->peak_force_kN;
    j["peak_displacement_mm"] = metrics->peak_displacement_mm;
    j["accel_extrapolation_rms_err_pct"] = metrics->accel_extrapolation_rms_err_pct;
    j["velocity_prediction_rms_err_pct"] = metrics->velocity_prediction_rms_err_pct;
    j["duplicates_logged"] = duplicates_logged;
  }
  if (!log_error.empty()) j["log_error"] = log_error;
  if (benchmark_criteria) {
    const signal::BenchmarkCriteria& c = *benchmark_criteria;
    nlohmann::json b = {{"J1_ms", c.J1_ms},   {"J2_pct", c.J2_pct}, {"J3_pct", c.J3_pct},
                        {"J4_pct", c.J4_pct}, {"J5_pct", c.J5_pct}, {"J6_pct", c.J6_pct},
                        {"J7_pct", c.J7_pct}, {"J8_pct", c.J8_pct}, {"J9_pct", c.J9_pct},
                        {"lag_samples", c.lag_samples}};
    b["floors"] = nlohmann::json::array();  // which floors J6-J9 are (every floor but the actuator's)
    for (const auto& f : c.floors) b["floors"].push_back({{"floor", f.floor}, {"std_pct", f.std_pct}, {"max_pct", f.max_pct}});
    j["benchmark_criteria"] = b;
  }
  if (!benchmark_error.empty()) j["benchmark_criteria_error"] = benchmark_error;
  if (marths) {
    nlohmann::json m = nlohmann::json::object();
    for (const auto& [key, value] : marths->j.Items()) m[key] = value;
    j["marths_criteria"] = m;
    j["marths_realizable"] = {{"realizable", marths->realizable},
                              {"max_volts", {marths->max_volts[0], marths->max_volts[1]}},
                              {"limit_volts", signal::kMarthsVoltLimit}};
  }
  if (!marths_error.empty()) j["marths_criteria_error"] = marths_error;
  if (structure_response) {
    const participants::StructureResponse& r = *structure_response;
    j["structure_peak_displacement_mm"] = r.peak_displacement_mm;
    j["structure_residual_displacement_mm"] = r.residual_displacement_mm;
    j["structure_hysteretic_energy_kN_mm"] = r.hysteretic_energy_kN_mm;
    j["structure_floor"] = r.floor;
    j["structure_peak_drift_mm"] = r.peak_drift_mm;
    j["structure_peak_drift_story"] = r.story;
    j["structure_ductility"] = r.ductility;
  }
  if (!structure_error.empty()) j["structure_error"] = structure_error;
  j["status"] = status;
  j["exit_code"] = exit_code;
  j["stopped"] = stopped;
  if (failure) {
    j["failure"] = {{"participant", failure->participant},
                    {"step", failure->step},
                    {"what", failure->what},
                    {"exit_code", failure->exit_code}};
    if (failure->teardown_s) j["failure"]["teardown_s"] = *failure->teardown_s;
  }
  j["link"] = StatsToJson(link);
  if (!realtime.is_null()) j["realtime"] = realtime;
  j["participants"] = nlohmann::json::object();
  for (const Outcome& o : participants) {
    nlohmann::json p = OutcomeToJson(o);
    p.erase("role");
    j["participants"][o.role] = p;
  }
  return j;
}

std::string RunSummary::Report(double dt_s) const {
  std::string o = fmt::format("  steps              {} of {}\n", steps, steps_expected);
  if (metrics && steps == 0) {
    o += "  tracking error     - (no step completed)\n";
  } else if (metrics) {
    o += fmt::format("  tracking error     {:.3f} % (RMS, Eq. 31)\n", metrics->tracking_nrmse_pct);
    o += fmt::format("  peak specimen force {:.2f} kN\n", metrics->peak_force_kN);
    o += fmt::format("  rate               {:.0f} steps/s ({:.2f}x real time)\n", steps_per_s(),
                     steps_per_s() * dt_s);
  }
  if (benchmark_criteria) o += "  benchmark          " + benchmark_criteria->Format() + "\n";
  if (!benchmark_error.empty()) o += "  benchmark          no J1-J9: " + benchmark_error + "\n";
  if (marths) {
    const signal::MarthsCriteria& c = marths->j;
    o += fmt::format("  maRTHS             J2 {:.3g} / {:.3g} %, J5 X {:.3g} %, TH {:.3g} %, J7 X {:.3g} %, TH {:.3g} % "
                     "(docs/marths.md); largest commands {:.3f} / {:.3f} V: {}\n",
                     c.J2_1_pct, c.J2_2_pct, c.J5_X_pct, c.J5_TH_pct, c.J7_X_pct, c.J7_TH_pct, marths->max_volts[0],
                     marths->max_volts[1], marths->realizable ? "realizable" : "NOT realizable (both above 3.8 V)");
  }
  if (!marths_error.empty()) o += "  maRTHS             no J1-J10: " + marths_error + "\n";
  if (structure_response) {
    const participants::StructureResponse& r = *structure_response;
    o += fmt::format("  structure          floor {}: peak {:.4g} mm, residual {:.4g} mm; story {}: peak drift {:.4g} mm "
                     "(ductility {:.3g}); hysteretic energy {:.4g} kN mm\n",
                     r.floor, r.peak_displacement_mm, r.residual_displacement_mm, r.story, r.peak_drift_mm, r.ductility,
                     r.hysteretic_energy_kN_mm);
  }
  if (!structure_error.empty()) o += "  structure          " + structure_error + "\n";
  if (realtime.is_object() && realtime.contains("steps")) {
    const auto& rt = realtime;
    const double period_us = rt["period_us"].get<double>();
    const int processes = rt.value("processes", 0);
    std::string setup = fmt::format("SCHED_FIFO {} in {} of {} process(es), memory locked in {} of {}",
                                    rt.value("priority", 0), rt.value("sched_fifo_processes", 0), processes,
                                    rt.value("memory_locked_processes", 0), processes);
    if (const std::string notes = rt.value("setup_notes", std::string()); !notes.empty()) {
      setup += "\n  NOT real-time      " + notes;
    }
    o += fmt::format("  real time          paced at {:.0f} Hz (dt {:g} ms); {}\n", 1e6 / period_us, period_us / 1e3,
                     setup);
    o += fmt::format("  step latency       p50 {:.0f} us, p99 {:.0f} us, p99.9 {:.0f} us, max {:.0f} us "
                     "(request to barrier)\n",
                     rt["latency_p50_us"].get<double>(), rt["latency_p99_us"].get<double>(),
                     rt["latency_p999_us"].get<double>(), rt["latency_max_us"].get<double>());
    o += fmt::format("  deadline misses    {} of {} steps ({:.4f} %), longest run {}\n",
                     rt["deadline_misses"].get<std::int64_t>(), rt["steps"].get<std::int64_t>(),
                     100.0 * rt["miss_fraction"].get<double>(), rt["max_consecutive_misses"].get<std::int64_t>());
  }
  if (link.rerequests > 0) {
    o += fmt::format("  link               {} re-requests, {} messages repaired\n", link.rerequests, link.repaired);
  }
  for (const Outcome& p : participants) {
    if (p.output_stalls <= 0) continue;
    o += fmt::format("  output             {} step(s) waited for signals.csv's writer thread (its queue was full: a "
                     "slow disk under --out?)\n",
                     p.output_stalls);
  }
  return o;
}

namespace {
/// steps, metrics and duplicates_logged from a log that was read. Throws what ComputeMetrics throws.
void ReadLog(const io::RunLog& log, RunSummary* s) {
  const io::RunMetrics m = io::ComputeMetrics(log);
  s->steps = m.steps;
  s->metrics = m;
  s->duplicates_logged = 0;
  for (const auto& [channel, n] : log.duplicates) s->duplicates_logged += n;
  s->log_error.clear();
}
}  // namespace

void ReadLog(const std::string& log_path, RunSummary* s) {
  try {
    ReadLog(io::ReadRunLog(log_path), s);
  } catch (const std::exception& e) {
    s->steps = 0;
    s->metrics.reset();
    s->log_error = e.what();
  }
}

void ReadLog(const std::string& log_path, const scenario::Scenario& scenario, RunSummary* s) {
  s->benchmark_criteria.reset();
  s->benchmark_error.clear();
  s->structure_response.reset();
  s->structure_error.clear();
  s->marths.reset();
  s->marths_error.clear();
  const bool benchmark = !scenario.structure.reference_file.empty() && !scenario.marths.enabled;
  const bool stepped = scenario.structure.Stepped() && !scenario.marths.enabled;
  if (!benchmark && !stepped && !scenario.marths.enabled) {
    ReadLog(log_path, s);
    return;
  }
  // Each score's own failure is said beside it (never thrown); a log that cannot be read is log_error.
  auto score = [](auto compute, auto* value, std::string* error) {
    try {
      *value = compute();
    } catch (const std::exception& e) {
      *error = e.what();
    }
  };
  try {
    const io::RunLog log = io::ReadRunLog(log_path);
    ReadLog(log, s);
    if (benchmark) score([&] { return BenchmarkCriteriaOfRun(log, scenario); }, &s->benchmark_criteria, &s->benchmark_error);
    if (stepped) {
      score([&] { return participants::StructureResponseOfRun(log, scenario); }, &s->structure_response,
            &s->structure_error);
    }
    if (scenario.marths.enabled) {
      score([&] { return participants::MarthsScoreOfRun(log, scenario); }, &s->marths, &s->marths_error);
    }
  } catch (const std::exception& e) {
    s->steps = 0;
    s->metrics.reset();
    s->log_error = e.what();
  }
}

void SetOutcomes(const std::vector<Outcome>& outcomes, RunSummary* s) {
  s->participants = outcomes;
  s->stepping_s = 0.0;
  s->link = {};
  lockstep::LinkStats& t = s->link;
  for (const Outcome& o : outcomes) {
    s->stepping_s = std::max(s->stepping_s, o.stepping_s);
    if (!o.stats_known) continue;
    const lockstep::LinkStats& l = o.stats;
    t.rerequests += l.rerequests;
    t.steps_rerequested += l.steps_rerequested;
    t.repair_requests += l.repair_requests;
    t.resent += l.resent;
    t.repaired += l.repaired;
    t.duplicates += l.duplicates;
    t.stale += l.stale;
    t.foreign += l.foreign;
    t.injected.dropped += l.injected.dropped;
    t.injected.duplicated += l.injected.duplicated;
    t.injected.delayed += l.injected.delayed;
    t.injected.reordered += l.injected.reordered;
  }
}

void SetVerdict(Verdict verdict, bool interrupted, RunSummary* s) {
  if (verdict.failed && verdict.step < 0 && verdict.exit_code > 128 && s->steps < s->steps_expected) {
    verdict.step = s->steps;  // a process that died cannot say where: the step it did not finish
    verdict.what += fmt::format(" during step {}", s->steps);
  }
  s->exit_code = 0;
  s->status = "completed";
  if (interrupted) {
    s->status = "interrupted";
    s->exit_code = kExitInterrupted;
  } else if (verdict.failed) {
    s->exit_code = verdict.exit_code != 0 ? verdict.exit_code : rths::kExitLockstep;
    s->status = s->exit_code == rths::kExitSafety     ? "stopped by the safety monitor"
                : s->exit_code == rths::kExitRealtime ? "stopped by the miss policy"
                : s->exit_code == rths::kExitPeerAbort ? "aborted"
                                                           : "failed";
  }
  s->stopped = interrupted ? std::string("interrupted by the user") : verdict.failed ? verdict.what : "no";
  s->failure.reset();
  if (verdict.failed) s->failure = RunSummary::Failure{verdict.role, verdict.step, verdict.what, verdict.exit_code, {}};
}

}  // namespace rths::supervisor
