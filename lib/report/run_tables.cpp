// The run report's tables and banner (report/run_tables.h).
#include "report/run_tables.h"

#include <cstdint>

#include <fmt/format.h>

#include "core/names.h"
#include "report/html.h"
#include "signal/metrics.h"

namespace rths::report::run_tables {

namespace {

std::string Pct(double v) { return fmt::format("{:.4g} %", v); }

}  // namespace

std::optional<double> JsonNumber(const nlohmann::json& j, const char* key) {
  if (j.is_object() && j.contains(key) && j[key].is_number()) return j[key].get<double>();
  return std::nullopt;
}

std::string JsonText(const nlohmann::json& j, const char* key, const std::string& fallback) {
  if (j.is_object() && j.contains(key) && j[key].is_string()) return j[key].get<std::string>();
  return fallback;
}


std::string ScenarioTable(const RunData& d) {
  std::string h;
  h += HtmlRow("scenario file", HtmlEscape(JsonText(d.summary, "scenario", (d.run_dir / "scenario.toml").string())));
  if (!d.scenario) {
    h += HtmlRow("settings", d.scenario_toml.empty() ? "no scenario.toml in the run folder"
                                                 : "scenario.toml does not load here: " + HtmlEscape(d.scenario_error));
    return h;
  }
  const scenario::Scenario& s = *d.scenario;
  h += HtmlRow("name", HtmlEscape(s.run.name));
  h += HtmlRow("step, duration",
           fmt::format("dt = {:g} s ({:g} Hz), {:g} s, {} steps", s.run.dt_s, 1.0 / s.run.dt_s, s.run.duration_s, s.steps()));
  const auto& c = s.controller;
  std::string ctrl(NameOf(control::kControllerKindNames, c.kind));
  if (c.kind == control::ControllerKind::kFf || c.kind == control::ControllerKind::kFfLp ||
      c.kind == control::ControllerKind::kFfLqg)
    ctrl += ", design model " + c.model.name;
  if (c.kind == control::ControllerKind::kFfLp || c.kind == control::ControllerKind::kBumplessLp)
    ctrl += fmt::format(", low-pass {:g} Hz order {}", c.lp_cutoff_hz, c.lp_order);
  if (c.kind == control::ControllerKind::kPoly3 || c.kind == control::ControllerKind::kLead)
    ctrl += fmt::format(", delay {:g} ms", c.delay_ms);
  h += HtmlRow("controller", HtmlEscape(ctrl));
  const auto& p = s.plant;
  std::string plant(NameOf(models::kPlantKindNames, p.kind));
  if (p.kind == models::PlantKind::kLinear) plant += ", actuator " + p.actuator.name;
  if (p.kind == models::PlantKind::kBenchmark) {  // the specimen is inside Gp: the experimental substructure
    const auto& b = p.benchmark.params;
    plant += fmt::format(", experimental substructure m_e {:g} kg, k_e {:g} N/m, zeta_e {:g}{}", b.m_e_kg, b.k_e_N_per_m,
                         b.zeta_e, p.benchmark.daq.enabled ? ", DAQ on" : "");
  } else {
    plant += ", specimen " + std::string(NameOf(models::kSpecimenNames, p.specimen));
  }
  if (p.RigMode()) plant += ", rig mode (effects on)";
  if (p.noise_y_mm_rms > 0 || p.noise_f_kN_rms > 0)
    plant += fmt::format(", sensor noise {:g} mm / {:g} kN RMS", p.noise_y_mm_rms, p.noise_f_kN_rms);
  h += HtmlRow("plant", HtmlEscape(plant));
  const auto& st = s.structure;
  std::string structure(NameOf(models::kStructureModeNames, st.mode));
  const signal::SignalSpec* exc = &st.ground;
  std::string exc_unit = "mm/s^2";
  if (st.mode == models::StructureMode::kPredefined) {
    structure += " (r from a history)";
    exc = &st.desired;
    exc_unit = "mm";
  } else if (st.kind == models::StructureKind::kSdof) {
    structure += fmt::format(", SDOF {:g} kg, {:g} Hz, {:g} % damping, {:g} specimen(s)", st.mass_kg,
                             st.frequency_hz, 100.0 * st.damping_ratio, st.specimen_count);
  } else {
    structure += fmt::format(", file {} (specimen at DOF {}), {:g} specimen(s)", st.file, st.actuator_dof,
                             st.specimen_count);
  }
  h += HtmlRow("structure", HtmlEscape(structure));
  std::string excitation = (st.mode == models::StructureMode::kPredefined ? "desired displacement: "
                                                                           : "ground acceleration: ") +
                           std::string(NameOf(signal::kSignalKindNames, exc->kind));
  if (exc->kind == signal::SignalKind::kBlwn)
    excitation += fmt::format(", 0-{:g} Hz, RMS {:g} {}, seed {}", exc->band_hz, exc->rms, exc_unit, exc->seed);
  else if (exc->kind == signal::SignalKind::kFile)
    excitation += fmt::format(", {} x {:g}", exc->file, exc->scale);
  h += HtmlRow("excitation", HtmlEscape(excitation));
  const auto& sa = s.semiactive;
  h += HtmlRow("damper current",
           HtmlEscape(fmt::format("{}, max {:g} A", NameOf(control::kSemiactiveModeNames, sa.mode), sa.max_current_A)));
  h += HtmlRow("real time", s.realtime.enabled ? "paced to the wall clock ([realtime] enabled)" : "not paced");
  return h;
}


std::string MetricsTable(const RunData& d) {
  const nlohmann::json& j = d.summary;
  const auto& sig = d.signals;
  const std::int64_t steps = static_cast<std::int64_t>(sig.steps());
  std::string h;
  if (j.is_object()) {
    const int code = j.value("exit_code", -1);
    std::string status = HtmlEscape(JsonText(j, "status", "?")) + fmt::format(" (exit code {})", code);
    const std::string stopped = JsonText(j, "stopped", "no");
    if (stopped != "no") status += ": " + HtmlEscape(stopped);
    h += HtmlRow("status", status, "status");
  } else {
    h += HtmlRow("status", d.log_complete ? "unknown (no summary.json); the log is complete"
                                      : "unknown (no summary.json); the log is truncated");
  }
  h += HtmlRow("steps", fmt::format("{} of {} ({:.4g} s of {:.4g} s)", steps, d.steps_planned,
                                static_cast<double>(steps) * sig.dt_s, static_cast<double>(d.steps_planned) * sig.dt_s),
           "steps");
  // Eq. 31 and the peaks: summary.json's (what `rths run` printed), else the log's.
  const double nrmse = JsonNumber(j, "tracking_nrmse_pct").value_or(d.metrics.tracking_nrmse_pct);
  const double peak_f = JsonNumber(j, "peak_force_kN").value_or(d.metrics.peak_force_kN);
  const double peak_y = JsonNumber(j, "peak_displacement_mm").value_or(d.metrics.peak_displacement_mm);
  h += HtmlRow("tracking error (RMS, Eq. 31)", Pct(nrmse), "tracking_nrmse_pct");
  h += HtmlRow("peak |f|", fmt::format("{:.4g} kN", peak_f), "peak_force_kN");
  h += HtmlRow("peak |y|", fmt::format("{:.4g} mm", peak_y), "peak_displacement_mm");
  if (steps > 0) {
    std::size_t at = 0;
    const double pe = signal::PeakAbs(sig.At("e_mm").values, &at);
    h += HtmlRow("peak |r|", fmt::format("{:.4g} mm", signal::PeakAbs(sig.At("r_mm").values)));
    h += HtmlRow("tracking error e = r - y", fmt::format("RMS {:.4g} mm, peak |e| {:.4g} mm at t = {:.4f} s",
                                                     signal::Rms(sig.At("e_mm").values), pe, sig.At("t_s").values[at]));
    h += HtmlRow("peak |i_eff|", fmt::format("{:.4g} A", signal::PeakAbs(sig.At("i_eff_A").values)));
  }
  h += HtmlRow("Eq. 20 acceleration extrapolation error",
           Pct(JsonNumber(j, "accel_extrapolation_rms_err_pct").value_or(d.metrics.accel_extrapolation_rms_err_pct)));
  h += HtmlRow("Eq. 21 velocity prediction error",
           Pct(JsonNumber(j, "velocity_prediction_rms_err_pct").value_or(d.metrics.velocity_prediction_rms_err_pct)));
  if (!j.is_object()) return h;
  if (const auto rate = JsonNumber(j, "steps_per_s"); rate && *rate > 0)
    h += HtmlRow("rate", fmt::format("{:.0f} steps/s ({:.3g}x real time), {} transport, {:.3g} s wall", *rate,
                                 *rate * sig.dt_s, HtmlEscape(JsonText(j, "transport", "?")),
                                 JsonNumber(j, "wall_s").value_or(0.0)));
  if (j.contains("link") && j["link"].is_object()) {
    const auto& l = j["link"];
    h += HtmlRow("link", fmt::format("{} re-requests, {} messages repaired, {} duplicates ignored; {} duplicates logged",
                                 l.value("rerequests", 0), l.value("repaired", 0), l.value("duplicates_ignored", 0),
                                 j.value("duplicates_logged", 0)));
  }
  if (j.contains("failure") && j["failure"].is_object()) {
    const auto& f = j["failure"];
    h += HtmlRow("failure", HtmlEscape(fmt::format("{} at step {}: {} (exit code {})", f.value("participant", "?"),
                                               f.value("step", -1), f.value("what", ""), f.value("exit_code", 0))));
  }
  if (j.contains("participants") && j["participants"].is_object()) {
    std::string ps;
    for (const auto& [role, p] : j["participants"].items()) {
      if (!ps.empty()) ps += ", ";
      ps += fmt::format("{} {}", role, p.is_object() ? p.value("exit_code", -1) : -1);
    }
    h += HtmlRow("participants (exit codes)", HtmlEscape(ps));
  }
  return h;
}

std::string RealtimeTable(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains("realtime") || !j["realtime"].is_object()) return "";
  const auto& rt = j["realtime"];
  if (!rt.contains("steps")) return "";
  const double period_us = rt.value("period_us", 0.0);
  std::string h = "<h2 id=\"realtime\">Real time</h2>\n<table>\n";
  h += HtmlRow("paced at", fmt::format("{:.0f} Hz (dt {:g} ms)", period_us > 0 ? 1e6 / period_us : 0.0, period_us / 1e3));
  const int processes = rt.value("processes", 0);
  std::string setup = fmt::format("SCHED_FIFO {} in {} of {} process(es), memory locked in {} of {}",
                                  rt.value("priority", 0), rt.value("sched_fifo_processes", 0), processes,
                                  rt.value("memory_locked_processes", 0), processes);
  if (const std::string notes = rt.value("setup_notes", std::string()); !notes.empty())
    setup += "; NOT real-time: " + notes;
  h += HtmlRow("set-up", HtmlEscape(setup));
  h += HtmlRow("step latency (request to barrier)",
           fmt::format("p50 {:.0f} us, p99 {:.0f} us, p99.9 {:.0f} us, max {:.0f} us", rt.value("latency_p50_us", 0.0),
                       rt.value("latency_p99_us", 0.0), rt.value("latency_p999_us", 0.0),
                       rt.value("latency_max_us", 0.0)),
           "latency");
  h += HtmlRow("deadline misses",
           fmt::format("{} of {} steps ({:.4f} %), longest run {}, first at step {}",
                       rt.value("deadline_misses", std::int64_t{0}), rt.value("steps", std::int64_t{0}),
                       100.0 * rt.value("miss_fraction", 0.0), rt.value("max_consecutive_misses", std::int64_t{0}),
                       rt.value("first_miss_step", std::int64_t{-1})),
           "deadline_misses");
  h += HtmlRow("latest release", fmt::format("{:.0f} us after its deadline", rt.value("max_release_late_us", 0.0)));
  return h + "</table>\n";
}

std::vector<std::string> Warnings(const RunData& d, bool* failed) {
  std::vector<std::string> w;
  const auto steps = static_cast<std::int64_t>(d.signals.steps());
  const bool has_summary = d.summary.is_object();
  const std::string status = has_summary ? JsonText(d.summary, "status", "?") : "";
  const int code = has_summary ? d.summary.value("exit_code", -1) : 0;
  const bool bad_status = has_summary && (status != "completed" || code != 0);
  *failed = !d.log_complete || bad_status || !d.abort_reason.empty();
  if (*failed) {
    // One headline: how it ended (summary.json), why (summary.json's `stopped`, else the log's ABORT).
    std::string why = has_summary ? JsonText(d.summary, "stopped", "no") : "no";
    if (why == "no") why = d.abort_reason;
    std::string line = "This run did not finish";
    if (bad_status) line += fmt::format(": {} (exit code {})", status, code);
    line += why.empty() ? (d.log_complete ? "" : " (log.lcm: " + d.truncation_reason + ")") : ": " + why;
    w.push_back(line + ".");
    w.push_back(fmt::format("Its log holds {} complete step(s) of {} planned ({:.4g} s of {:.4g} s): everything "
                            "below covers those steps.",
                            steps, d.steps_planned, static_cast<double>(steps) * d.signals.dt_s,
                            static_cast<double>(d.steps_planned) * d.signals.dt_s));
    if (!why.empty() && !d.log_complete) w.push_back("log.lcm: " + d.truncation_reason);
  }
  // A paced run that missed deadlines did not run in real time, even if it completed: the
  // banner says so (a note, not green), with how long the worst stretch lasted.
  if (has_summary && d.summary.contains("realtime") && d.summary["realtime"].is_object()) {
    const auto& rt = d.summary["realtime"];
    const auto misses = rt.value("deadline_misses", std::int64_t{0});
    if (rt.value("paced", false) && misses > 0) {
      const auto longest = rt.value("max_consecutive_misses", std::int64_t{0});
      w.push_back(fmt::format("NOT real time: this paced run missed {} of {} deadlines ({:.3g} %); the longest "
                              "stretch was {} steps in a row ({:.3g} ms), the largest step latency {:.3g} ms, the "
                              "first miss at step {}.",
                              misses, rt.value("steps", std::int64_t{0}), 100.0 * rt.value("miss_fraction", 0.0),
                              longest, static_cast<double>(longest) * d.signals.dt_s * 1e3,
                              rt.value("latency_max_us", 0.0) / 1e3, rt.value("first_miss_step", std::int64_t{-1})));
    }
  }
  if (!has_summary) {
    w.push_back(d.summary_error + ": how the run ended (status, exit code), link and real-time figures are unknown; "
                "the numbers below come from the log");
  }
  if (!d.scenario_error.empty()) w.push_back("scenario.toml does not load here: " + d.scenario_error);
  if (d.scenario_toml.empty()) w.push_back("no scenario.toml in the run folder");
  for (const auto& n : d.notes) w.push_back(n);
  return w;
}


}  // namespace rths::report::run_tables
