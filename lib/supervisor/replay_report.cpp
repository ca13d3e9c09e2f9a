#include "supervisor/replay_report.h"

#include "io/log_compare.h"
#include "participants/replay.h"

namespace rths::supervisor {

namespace {

nlohmann::json DiffToJson(const std::string& role, const io::ChannelDiff& d) {
  nlohmann::json c = {{"role", role},
                      {"steps_compared", d.steps},
                      {"identical", d.identical()},
                      {"first_difference_step", d.first_difference},
                      {"differing_steps", d.differing_steps}};
  nlohmann::json fields = nlohmann::json::object();
  for (const auto& f : d.fields) {
    fields[f.name] = {{"rms", f.rms}, {"peak", f.peak}, {"peak_step", f.peak_step}, {"recorded_rms", f.rms_a}};
  }
  c["fields"] = fields;
  return c;
}

/// Compares every live channel; fills replayed, channels, identical and lines.
void Compare(const ReplayFacts& facts, const io::RunLog& record, const std::filesystem::path& out, ReplayReport* r) {
  const auto replay = io::ReadRunLog((out / "log.lcm").string());
  r->replayed = replay.CompleteSteps();
  r->json["steps_replayed"] = r->replayed;
  nlohmann::json channels = nlohmann::json::object();
  r->identical = true;
  for (const auto& role : facts.live) {
    const std::string ch = participants::AnswerChannelOf(role);
    const auto d = io::CompareChannel(record, replay, ch, r->replayed);
    channels[ch] = DiffToJson(role, d);
    if (!d.identical()) r->identical = false;
    r->lines.push_back("live " + role + ": " + io::Describe(d));
  }
  r->json["channels"] = channels;
  r->json["identical"] = r->identical;
  r->compared = true;
}

}  // namespace

ReplayReport CompareReplay(const ReplayFacts& facts, const io::RunLog& record, const std::filesystem::path& out,
                           const std::vector<participants::Outcome>& outcomes, bool interrupted) {
  ReplayReport r;
  r.verdict = participants::Judge(outcomes);
  r.interrupted = interrupted;
  r.failed = r.verdict.failed || interrupted;
  r.json["run_dir"] = facts.run_dir;
  r.json["live"] = facts.live;
  r.json["steps"] = facts.steps;
  r.json["scenario_sha256"] = facts.scenario_sha256;
  r.json["recorded_scenario_sha256"] = facts.recorded_scenario_sha256;
  if (r.failed) {
    r.json["status"] = interrupted ? "interrupted" : "failed";
    r.json["failure"] = {{"participant", r.verdict.role}, {"step", r.verdict.step}, {"what", r.verdict.what}};
  }
  try {
    Compare(facts, record, out, &r);
  } catch (const std::exception& e) {
    r.identical = false;
    r.log_error = e.what();
    r.json["log_error"] = r.log_error;
  }
  return r;
}

nlohmann::json ReplayReport::ToJson(int exit_code) const {
  nlohmann::json j = json;
  if (!failed) j["status"] = "completed";
  j["exit_code"] = exit_code;
  return j;
}

}  // namespace rths::supervisor
