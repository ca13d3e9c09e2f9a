#include "participants/group.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include <fmt/core.h>

#include "core/error.h"
#include "lockstep/clock.h"
#include "lockstep/step_table.h"
#include "lockstep/bridge.h"
#include "lockstep/transport.h"
#include "participants/factory.h"

namespace rths::participants {

nlohmann::json StatsToJson(const lockstep::LinkStats& s) {
  return {{"rerequests", s.rerequests},
          {"steps_rerequested", s.steps_rerequested},
          {"repair_requests", s.repair_requests},
          {"resent", s.resent},
          {"repaired", s.repaired},
          {"duplicates_ignored", s.duplicates},
          {"stale_ignored", s.stale},
          {"foreign_ignored", s.foreign},
          {"injected",
           {{"dropped", s.injected.dropped},
            {"duplicated", s.injected.duplicated},
            {"delayed", s.injected.delayed},
            {"reordered", s.injected.reordered}}}};
}

namespace {
/// The latency over the run: per window (steps k = i window_steps ..), the largest latency [us]
/// and the misses; the windows the run reached.
nlohmann::json LatencyWindowsJson(const lockstep::RealtimeStats& r) {
  nlohmann::json max_us = nlohmann::json::array(), misses = nlohmann::json::array();
  const std::int64_t reached = r.window_steps > 0 ? (r.steps + r.window_steps - 1) / r.window_steps : 0;
  for (std::int64_t w = 0; w < reached && w < static_cast<std::int64_t>(r.window_max_s.size()); ++w) {
    max_us.push_back(std::round(1e7 * r.window_max_s[static_cast<std::size_t>(w)]) / 10.0);  // 0.1 us
    misses.push_back(r.window_misses[static_cast<std::size_t>(w)]);
  }
  return {{"window_steps", r.window_steps}, {"max_us", max_us}, {"misses", misses}};
}
}  // namespace

nlohmann::json RealtimeToJson(const lockstep::RealtimeStats& r) {
  const auto& h = r.latency;
  nlohmann::json bins = nlohmann::json::array();
  for (int i = 0; i < lockstep::LatencyHistogram::kBins; ++i) {
    if (h.bin(i) == 0) continue;
    const double hi = lockstep::LatencyHistogram::UpperEdge(i);
    bins.push_back({1e6 * lockstep::LatencyHistogram::LowerEdge(i), std::isfinite(hi) ? 1e6 * hi : -1.0, h.bin(i)});
  }
  return {{"paced", r.paced},
          {"period_us", 1e6 * r.period_s},
          {"steps", r.steps},
          {"deadline_misses", r.misses},
          {"miss_fraction", r.steps > 0 ? static_cast<double>(r.misses) / static_cast<double>(r.steps) : 0.0},
          {"max_consecutive_misses", r.max_consecutive_misses},
          {"first_miss_step", r.first_miss_step},
          {"latency_p50_us", 1e6 * h.Quantile(0.5)},
          {"latency_p99_us", 1e6 * h.Quantile(0.99)},
          {"latency_p999_us", 1e6 * h.Quantile(0.999)},
          {"latency_max_us", 1e6 * h.max_s()},
          {"max_release_late_us", 1e6 * r.max_release_late_s},
          {"latency_histogram_us", bins},
          {"latency_windows", LatencyWindowsJson(r)}};
}

namespace {
nlohmann::json PeerToJson(const lockstep::PeerObservation& p) {
  nlohmann::json j = {{"pid", p.pid},
                      {"heartbeat_s", p.heartbeat_s},
                      {"hello", p.hello},
                      {"bye", p.bye},
                      {"aborted", p.aborted},
                      {"abort_reason", p.abort_reason},
                      {"answers", p.answers},
                      {"duplicates", p.duplicates},
                      {"rerequests", p.rerequests},
                      {"repair_requests", p.repair_requests},
                      {"lost", p.lost}};
  if (p.lost) {
    j["loss"] = {{"died", p.loss.died},         {"status_known", p.loss.status_known},
                 {"exit_code", p.loss.exit_code}, {"signal", p.loss.signal},
                 {"silent_s", p.loss.silent_s},  {"what", p.loss.what}};
  }
  return j;
}

lockstep::PeerObservation PeerFromJson(const nlohmann::json& j) {
  lockstep::PeerObservation p;
  p.pid = j.value("pid", 0);
  p.heartbeat_s = j.value("heartbeat_s", 0.0);
  p.hello = j.value("hello", false);
  p.bye = j.value("bye", false);
  p.aborted = j.value("aborted", false);
  p.abort_reason = j.value("abort_reason", std::string());
  p.answers = j.value("answers", std::int64_t{0});
  p.duplicates = j.value("duplicates", std::int64_t{0});
  p.rerequests = j.value("rerequests", std::int64_t{0});
  p.repair_requests = j.value("repair_requests", std::int64_t{0});
  p.lost = j.value("lost", false);
  if (p.lost && j.contains("loss")) {
    const auto& l = j.at("loss");
    p.loss.died = l.value("died", false);
    p.loss.status_known = l.value("status_known", false);
    p.loss.exit_code = l.value("exit_code", 0);
    p.loss.signal = l.value("signal", 0);
    p.loss.silent_s = l.value("silent_s", 0.0);
    p.loss.what = l.value("what", std::string());
  }
  return p;
}
}  // namespace

nlohmann::json FollowToJson(const lockstep::FollowLedger& ledger) {
  const lockstep::FollowCounts c = ledger.Counts();
  nlohmann::json j = {{"n_steps", ledger.n_steps()}, {"messages", ledger.messages()}, {"exact", c.exact},
                      {"resumed", c.resumed},         {"held", c.held},                {"unseen", c.unseen},
                      {"ranges_truncated", false}};
  const std::pair<const char*, lockstep::FollowStep> classes[] = {{"held_steps", lockstep::FollowStep::kHeld},
                                                                  {"resumed_steps", lockstep::FollowStep::kResumed},
                                                                  {"unseen_steps", lockstep::FollowStep::kUnseen}};
  for (const auto& [key, cls] : classes) {
    const auto ranges = ledger.Ranges(cls);
    nlohmann::json list = nlohmann::json::array();
    for (std::size_t i = 0; i < ranges.size() && i < kFollowRangesKept; ++i) {
      list.push_back({ranges[i].first, ranges[i].second});
    }
    if (ranges.size() > kFollowRangesKept) j["ranges_truncated"] = true;
    j[key] = list;
  }
  return j;
}

Outcome OutcomeOf(const lockstep::Participant& p, Outcome o) {
  o.role = p.name();
  o.exit_code = p.exit_code();
  o.message = p.error();
  o.culprit = p.culprit();
  o.step = p.fail_step();
  o.stats = p.stats();
  o.stats_known = true;
  o.stepping_s = p.stepping_s();
  o.output_stalls = p.output_stalls();
  if (const auto* rt = p.realtime()) o.realtime = *rt;
  if (const auto* ledger = p.follow_ledger()) o.follow = FollowToJson(*ledger);
  if (const auto* peers = p.peers()) {
    for (int i = 0; i < lockstep::kRosterSize; ++i) {
      if (lockstep::kRoster[i] != p.name()) o.peers[std::string(lockstep::kRoster[i])] = (*peers)[i];
    }
  }
  return o;
}

nlohmann::json Outcome::RealtimeJson() const {
  if (realtime.steps > 0) return RealtimeToJson(realtime);
  return realtime_json;
}

nlohmann::json OutcomeToJson(const Outcome& o) {
  nlohmann::json j = {{"role", o.role},       {"exit_code", o.exit_code},
                      {"signal", o.signal},   {"message", o.message},
                      {"culprit", o.culprit}, {"step", o.step},
                      {"killed_by_supervisor", o.killed_by_supervisor},
                      {"was_stopped", o.was_stopped}};
  if (o.stepping_s > 0) j["stepping_s"] = o.stepping_s;
  if (o.output_stalls >= 0) j["output_stalls"] = o.output_stalls;
  if (o.external) {
    j["external"] = true;
    j["observed"] = o.observed;
  }
  if (o.realtime_setup.tried) {
    j["realtime_setup"] = {{"sched_fifo", o.realtime_setup.fifo},
                           {"priority", o.realtime_setup.priority},
                           {"memory_locked", o.realtime_setup.memory_locked},
                           {"cpu", o.realtime_setup.cpu},
                           {"note", o.realtime_setup.note}};
  }
  if (const nlohmann::json rt = o.RealtimeJson(); !rt.is_null()) j["realtime"] = rt;
  if (!o.follow.is_null()) j["follow"] = o.follow;
  if (o.stats_known) j["link"] = StatsToJson(o.stats);
  if (!o.peers.empty()) {
    nlohmann::json peers = nlohmann::json::object();
    for (const auto& [role, p] : o.peers) peers[role] = PeerToJson(p);
    j["peers"] = peers;
  }
  return j;
}

Outcome OutcomeFromJson(const nlohmann::json& j) {
  Outcome o;
  o.role = j.at("role").get<std::string>();
  o.exit_code = j.at("exit_code").get<int>();
  o.signal = j.value("signal", 0);
  o.message = j.value("message", std::string());
  o.culprit = j.value("culprit", std::string());
  o.step = j.value("step", std::int64_t{-1});
  o.killed_by_supervisor = j.value("killed_by_supervisor", false);
  o.was_stopped = j.value("was_stopped", false);
  o.stepping_s = j.value("stepping_s", 0.0);
  o.output_stalls = j.value("output_stalls", std::int64_t{-1});
  o.external = j.value("external", false);
  o.observed = j.value("observed", std::string());
  if (j.contains("peers")) {
    for (const auto& [role, p] : j.at("peers").items()) o.peers[role] = PeerFromJson(p);
  }
  if (j.contains("realtime_setup")) {
    const auto& r = j.at("realtime_setup");
    o.realtime_setup.tried = true;
    o.realtime_setup.fifo = r.value("sched_fifo", false);
    o.realtime_setup.priority = r.value("priority", 0);
    o.realtime_setup.memory_locked = r.value("memory_locked", false);
    o.realtime_setup.cpu = r.value("cpu", -1);
    o.realtime_setup.note = r.value("note", std::string());
  }
  if (j.contains("realtime")) o.realtime_json = j.at("realtime");
  if (j.contains("follow")) o.follow = j.at("follow");
  if (j.contains("link")) {
    const auto& l = j.at("link");
    lockstep::LinkStats& s = o.stats;
    s.rerequests = l.at("rerequests").get<std::int64_t>();
    s.steps_rerequested = l.at("steps_rerequested").get<std::int64_t>();
    s.repair_requests = l.at("repair_requests").get<std::int64_t>();
    s.resent = l.at("resent").get<std::int64_t>();
    s.repaired = l.at("repaired").get<std::int64_t>();
    s.duplicates = l.at("duplicates_ignored").get<std::int64_t>();
    s.stale = l.at("stale_ignored").get<std::int64_t>();
    s.foreign = l.at("foreign_ignored").get<std::int64_t>();
    const auto& in = l.at("injected");
    s.injected = {in.at("dropped").get<std::int64_t>(), in.at("duplicated").get<std::int64_t>(),
                  in.at("delayed").get<std::int64_t>(), in.at("reordered").get<std::int64_t>()};
    o.stats_known = true;
  }
  return o;
}

namespace {
/// Builds the participants of `per_role` (one scenario, or one per role in kBuildOrder) but those
/// in `skip`, attaches them to `channels` and runs them; their outcomes.
std::vector<Outcome> RunGroupOn(lockstep::Channels* channels, const std::vector<scenario::Scenario>& per_role,
                                const std::vector<std::string>& skip, std::int64_t run_id,
                                const std::string& out_dir, const std::vector<RoleFault>& faults,
                                const volatile std::sig_atomic_t* stop, lockstep::LiveSink* live) {
  const auto& order = lockstep::kBuildOrder;  // the logger subscribes before anyone publishes
  if (per_role.size() != 1 && per_role.size() != order.size()) {
    throw Error("RunGroupInProcess", "give one scenario, or one per role");
  }
  for (const auto& s : per_role) {
    const lockstep::ProcessFault kind = s.faults.process_kind;
    const bool elsewhere = std::find(skip.begin(), skip.end(), s.faults.process_role) != skip.end();
    if (lockstep::EndsProcess(kind) && !elsewhere) {
      throw Error(s.path + ": faults.process.kind",
                  fmt::format("\"{}\" would take every participant down in one process (memq): use the "
                              "udpm transport (one process per participant)",
                              NameOf(lockstep::kProcessFaultNames, kind)));
    }
  }
  std::vector<std::unique_ptr<lockstep::Participant>> owned;
  std::vector<lockstep::Participant*> group;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (std::find(skip.begin(), skip.end(), order[i]) != skip.end()) continue;
    const auto& s = per_role[per_role.size() == 1 ? 0 : i];
    lockstep::Faults f = FaultsOf(s, order[i]);
    for (const auto& extra : faults) {
      if (extra.role != order[i]) continue;
      f.targeted.insert(f.targeted.end(), extra.faults.targeted.begin(), extra.faults.targeted.end());
      f.command_gain = extra.faults.command_gain;
      if (extra.faults.process != lockstep::ProcessFault::kNone) {
        f.process = extra.faults.process;
        f.at_step = extra.faults.at_step;
        f.stop_s = extra.faults.stop_s;
      }
      if (extra.faults.network.any()) f.network = extra.faults.network;
    }
    owned.push_back(MakeParticipant(order[i], s, IdentityOf(s, run_id), nullptr, out_dir, std::move(f)));
    owned.back()->Attach(channels);
    if (auto* clock = dynamic_cast<lockstep::ClockParticipant*>(owned.back().get()); clock && live) {
      clock->SetLiveSink(live);
    }
    group.push_back(owned.back().get());
  }
  lockstep::RunLoop(channels, group, stop);
  std::vector<Outcome> outcomes;
  for (const auto* p : group) outcomes.push_back(OutcomeOf(*p));
  return outcomes;
}
}  // namespace

std::vector<Outcome> RunGroupInProcess(const std::vector<scenario::Scenario>& per_role,
                                       std::int64_t run_id, const std::string& out_dir,
                                       const std::vector<RoleFault>& faults,
                                       const volatile std::sig_atomic_t* stop, lockstep::LiveSink* live) {
  lockstep::InprocChannels bus;
  return RunGroupOn(&bus, per_role, {}, run_id, out_dir, faults, stop, live);
}

std::vector<Outcome> RunMixedGroup(const scenario::Scenario& s, const std::vector<std::string>& external,
                                   const std::string& udpm_url, std::int64_t run_id, const std::string& out_dir,
                                   const volatile std::sig_atomic_t* stop, lockstep::LiveSink* live) {
  lockstep::BridgedChannels bridge(udpm_url, external, WiringOf(s));
  if (!bridge.good()) throw Error("", bridge.error());
  return RunGroupOn(&bridge, {s}, external, run_id, out_dir, {}, stop, live);
}

namespace {
/// 4: killed by a signal it was not sent by the supervisor; 3: failed on its own; 2: detected a
/// lockstep failure; 1: was told to stop (or killed by the supervisor); 0: fine.
int Blame(const Outcome& o) {
  if (o.signal != 0) return o.killed_by_supervisor ? 1 : 4;
  switch (o.exit_code) {
    case rths::kExitOk: return 0;
    case rths::kExitPeerAbort: return 1;
    case rths::kExitLockstep: return 2;
    default: return 3;
  }
}

const Outcome* Find(const std::vector<Outcome>& outcomes, std::string_view role) {
  for (const auto& o : outcomes) {
    if (o.role == role) return &o;
  }
  return nullptr;
}
}  // namespace

const Outcome* RootCause(const std::vector<Outcome>& outcomes) {
  const Outcome* worst = nullptr;
  for (const auto& o : outcomes) {
    if (Blame(o) > 0 && (!worst || Blame(o) > Blame(*worst))) worst = &o;
  }
  return worst;
}

Verdict Judge(const std::vector<Outcome>& outcomes) {
  Verdict v;
  const Outcome* worst = RootCause(outcomes);
  if (!worst) return v;
  v.failed = true;
  if (Blame(*worst) == 2) {
    // A lockstep failure: the clock's diagnosis (it sees every answer) before a participant's
    // watchdog; blame whom it names.
    for (const auto& o : outcomes) {
      if (Blame(o) != 2) continue;
      if (o.role == "integrator") {
        worst = &o;
        break;
      }
      if (worst->culprit.empty() && !o.culprit.empty()) worst = &o;
    }
    v.role = worst->culprit.empty() ? worst->role : worst->culprit;
    v.exit_code = rths::kExitLockstep;
    v.step = worst->step;
    v.what = worst->message;
    if (const Outcome* c = Find(outcomes, v.role); c && c != worst) {
      if (c->killed_by_supervisor) {
        v.what += fmt::format("; the supervisor killed {} ({}){}", c->role,
                              c->signal ? strsignal(c->signal) : "signal",
                              c->was_stopped ? ": it was stopped (SIGSTOP) and did not answer the abort" : "");
      } else if (c->signal != 0) {
        v.what += fmt::format("; {} was killed by signal {} ({})", c->role, c->signal, strsignal(c->signal));
      } else if (c->exit_code != 0 && !c->message.empty()) {
        v.what += fmt::format("; {} then exited with code {}: {}", c->role, c->exit_code, c->message);
      }
    }
    if (v.role == "integrator" && v.what.find("integrator") == std::string::npos) {
      v.what = "integrator (the clock) stopped answering: " + v.what;
    }
    return v;
  }
  v.role = worst->role;
  v.step = worst->step;
  if (worst->signal != 0) {
    v.exit_code = 128 + worst->signal;
    v.what = fmt::format("{} was {} by signal {} ({})", worst->role,
                         worst->killed_by_supervisor ? "killed by the supervisor" : "killed",
                         worst->signal, strsignal(worst->signal));
    if (!worst->message.empty()) v.what += ": " + worst->message;
    return v;
  }
  v.exit_code = worst->exit_code;
  // Everyone was told to stop (an ABORT from outside the group: the monitor's Abort button, a
  // user's tool): the abort's own words, "<sender> aborted the run: <reason>".
  const bool told = worst->exit_code == rths::kExitPeerAbort && !worst->message.empty();
  v.what = (worst->external || told) && !worst->message.empty()
               ? worst->message
               : fmt::format("{} exited with code {}{}{}", worst->role, worst->exit_code,
                             worst->message.empty() ? "" : ": ", worst->message);
  return v;
}

}  // namespace rths::participants
