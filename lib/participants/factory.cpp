#include "participants/factory.h"

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "io/reserved_file.h"
#include "lockstep/transport.h"
#include "participants/controller.h"
#include "participants/group.h"
#include "participants/integrator.h"
#include "participants/logger.h"
#include "participants/plant.h"
#include "participants/semiactive.h"

namespace rths::participants {

namespace fs = std::filesystem;

lockstep::RunIdentity IdentityOf(const scenario::Scenario& s, std::int64_t run_id) {
  return {run_id, s.sha256, s.steps(), s.run.dt_s};
}

lockstep::Timing TimingOf(const scenario::Scenario& s) {
  lockstep::Timing t;
  t.rerequest_ms = s.lockstep.rerequest_ms;
  t.stall_budget_s = s.lockstep.stall_budget_s;
  t.handshake_timeout_s = s.lockstep.handshake_timeout_s;
  t.pacing = {s.realtime.enabled, s.run.dt_s, s.realtime.max_consecutive_misses};
  return t;
}

lockstep::Faults FaultsOf(const scenario::Scenario& s, std::string_view role) {
  const lockstep::FaultConfig& c = s.faults;
  lockstep::Faults f;
  f.network = {c.drop, c.duplicate, c.delay, c.reorder, c.delay_ms, static_cast<std::uint64_t>(c.seed)};
  if (c.process_role == role) {
    f.process = c.process_kind;
    f.at_step = c.process_at_step;
    f.stop_s = c.process_stop_s;
  }
  return f;
}

OutputBytes EstimateOutputBytes(const scenario::Scenario& s) {
  const int n_dof = s.structure.mode == models::StructureMode::kPredefined
                        ? 1
                        : static_cast<int>(models::StructureFromScenario(s.structure, s.path).M.rows());
  const double steps = static_cast<double>(s.steps());
  const double log_step = static_cast<double>(LogBytesPerStep(n_dof));
  const double row = static_cast<double>(StoredBytesPerStep(n_dof)) - log_step;
  OutputBytes b;
  b.log = steps * log_step;
  b.csv = s.run.csv_every > 0 ? std::ceil(steps / s.run.csv_every) * row : 0.0;
  return b;
}

bool PlantAnswersCommand(const scenario::Scenario& s) { return s.plant.kind != models::PlantKind::kIdeal; }

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir, lockstep::Faults faults) {
  if (role == "integrator") return std::make_unique<Integrator>(s, id, lcm, std::move(faults));
  if (role == "controller") return std::make_unique<Controller>(s, id, lcm, std::move(faults));
  if (role == "plant") return std::make_unique<Plant>(s, id, lcm, std::move(faults));
  if (role == "semiactive") return std::make_unique<Semiactive>(s, id, lcm, std::move(faults));
  if (role == "logger") {
    return std::make_unique<Logger>(id, TimingOf(s), lcm, out_dir + "/log.lcm", out_dir + "/signals.csv",
                                    std::move(faults), s.run.csv_every, PlantAnswersCommand(s));
  }
  throw Error("", fmt::format("unknown participant role '{}'", role));
}

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir) {
  return MakeParticipant(role, s, id, lcm, out_dir, FaultsOf(s, role));
}

void CheckBuildable(const scenario::Scenario& s) {
  for (std::string_view role : {"integrator", "controller", "plant", "semiactive"}) {
    MakeParticipant(role, s, IdentityOf(s, 1), nullptr, "", {});
  }
}

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnStopSignal(int) { g_stop = 1; }

/// Where a participant process leaves its outcome for the supervisor: `out_dir`/logs/<role>.json.
std::string OutcomePath(const std::string& out_dir, const std::string& role) {
  return (fs::path(out_dir) / "logs" / (role + ".json")).string();
}
/// Its space is reserved at start-up, so that a disk that fills up during the run cannot take it.
constexpr std::size_t kOutcomeReserve = 8192;
}  // namespace

int RoleMain(std::string_view role, int argc, char** argv) {
  const std::string name(role);
  CLI::App app{fmt::format("rths-{}: the {} participant of a lockstep run (started by `rths run`)",
                           name, name)};
  std::string scenario_path, url, out_dir = ".";
  std::int64_t run_id = 0;
  app.add_option("--scenario", scenario_path, "scenario TOML file")->required();
  app.add_option("--lcm-url", url, "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0")->required();
  app.add_option("--run-id", run_id, "run id shared by every participant")->required();
  app.add_option("--out", out_dir, "output folder (the logger's files; logs/<role>.json for everyone)");
  double handshake_timeout_s = 0;
  app.add_option("--handshake-timeout-s", handshake_timeout_s,
                 "wait this long for the handshake instead of the scenario's lockstep.handshake_timeout_s "
                 "(rths run --external: time for the external participants to join) [s]")
      ->check(CLI::Range(0.1, 86400.0));
  bool follow = false;
  double follow_idle_s = 2.0;
  app.add_flag("--follow", follow,
               "follow mode: no handshake, no clock; answer each step as soon as its inputs arrive (fed by "
               "lcm-logplayer from a recorded log, with that log's --run-id; docs/replay.md). Delivery is not "
               "guaranteed: a lost input stops the answers there");
  app.add_option("--follow-idle-s", follow_idle_s, "follow mode: finish after this long without a message [s]")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  bool realtime = false;
  app.add_flag("--realtime", realtime, "real-time paced mode, as if the scenario said [realtime] enabled = true");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : lockstep::kExitUsage;
  }
  // A file grown past RLIMIT_FSIZE must fail the write (EFBIG), not kill the process.
  std::signal(SIGXFSZ, SIG_IGN);
  // SIGTERM (the supervisor's teardown) or SIGINT (Ctrl-C reaches the whole process group): stop
  // at once, committed output flushed, and say so in the outcome.
  std::signal(SIGTERM, OnStopSignal);
  std::signal(SIGINT, OnStopSignal);
  Outcome o;
  o.role = name;
  io::ReserveFile(OutcomePath(out_dir, name), kOutcomeReserve, "{}\n");
  try {
    scenario::Scenario s = scenario::LoadScenario(scenario_path);
    // Not part of the handshake's identity (the hash is of the file): only how long to wait.
    if (handshake_timeout_s > 0) s.lockstep.handshake_timeout_s = handshake_timeout_s;
    if (realtime) s.realtime.enabled = true;  // pacing is not part of the identity either
    if (s.realtime.enabled) {
      o.realtime_setup = lockstep::EnterRealtime(s.realtime.sched_fifo, s.realtime.priority, s.realtime.lock_memory);
      if (!o.realtime_setup.note.empty()) std::fprintf(stderr, "%s: %s\n", name.c_str(), o.realtime_setup.note.c_str());
    }
    // Follow mode if asked, then the event loop on the participant's transport; its outcome.
    auto run = [&](lockstep::Participant* p, auto* transport) {
      if (follow) {
        if (role == "integrator") throw Error("--follow", "the integrator is the clock: it cannot follow");
        p->Follow(follow_idle_s);
      }
      const int rc = lockstep::RunLoop(transport, {p}, &g_stop);
      o = OutcomeOf(*p, o);
      if (o.exit_code == 0) o.exit_code = rc;  // e.g. the receive failed
    };
    if (lockstep::IsPortPerChannel(url)) {
      // One UDP port per channel (lockstep/transport.h): this process receives only its channels.
      lockstep::UdpmChannels channels(*lockstep::UdpmUrl::Parse(url));
      auto p = MakeParticipant(role, s, IdentityOf(s, run_id), nullptr, out_dir);
      std::string why = channels.error();
      if (why.empty()) {
        try {
          p->Attach(&channels);
        } catch (const std::runtime_error& e) {
          why = e.what();
        }
      }
      if (!why.empty()) {
        const std::string hint = lockstep::CheckMulticastRoute();
        o.exit_code = lockstep::kExitLockstep;
        o.message = fmt::format("cannot open the channels of {}: {}{}{}", url, why, hint.empty() ? "" : "\n", hint);
      } else {
        run(p.get(), static_cast<lockstep::Channels*>(&channels));
      }
    } else if (lcm::LCM lcm(url); !lcm.good()) {
      std::string hint = lockstep::CheckMulticastRoute();
      o.exit_code = lockstep::kExitLockstep;
      o.message = fmt::format("cannot open LCM at {}{}{}", url, hint.empty() ? "" : "\n", hint);
    } else {
      run(MakeParticipant(role, s, IdentityOf(s, run_id), &lcm, out_dir).get(), &lcm);
    }
  } catch (const Error& e) {
    o.exit_code = lockstep::kExitUsage;
    o.message = e.what();
  } catch (const std::exception& e) {
    o.exit_code = lockstep::kExitInternal;
    o.message = fmt::format("internal error: {}", e.what());
  }
  if (o.exit_code != 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), o.message.c_str());
  io::OverwriteFile(OutcomePath(out_dir, name), OutcomeToJson(o).dump(2) + "\n");
  return o.exit_code;
}

}  // namespace rths::participants
