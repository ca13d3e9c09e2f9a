#include "participants/factory.h"

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "io/reserved_file.h"
#include "lockstep/clock.h"
#include "lockstep/run_loop.h"
#include "lockstep/transport.h"
#include "participants/controller.h"
#include "participants/group.h"
#include "participants/integrator.h"
#include "participants/logger.h"
#include "participants/marths_participants.h"
#include "participants/plant.h"
#include "participants/semiactive.h"

namespace rths::participants {

namespace fs = std::filesystem;

lockstep::RunIdentity IdentityOf(const scenario::Scenario& s, std::int64_t run_id) {
  return {run_id, s.sha256, s.steps(), s.run.dt_s};
}

lockstep::LockstepConfig LockstepOf(const scenario::Scenario& s) {
  lockstep::LockstepConfig c = s.lockstep;
  c.pacing = {s.realtime.enabled, s.run.dt_s, s.realtime.max_consecutive_misses, 1e-6 * s.realtime.spin_us};
  return c;
}

lockstep::Wiring WiringOf(const scenario::Scenario& s) {
  if (s.marths.enabled) return lockstep::Wiring::Resolve({{"integrator", lockstep::kSameSampleVariant}});
  if (s.plant.kind == models::PlantKind::kIdeal) return lockstep::Wiring::Resolve({{"plant", lockstep::kIdealVariant}});
  return lockstep::Wiring::Resolve();
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

namespace {
/// The sizes of the per-step messages' arrays in a run of `s`: DOFs, actuators, interface forces.
struct ArraySizes {
  int n_dof = 1, n_act = 0, n_iface = 0;
};
ArraySizes ArraySizesOf(const scenario::Scenario& s) {
  if (s.marths.enabled) return {static_cast<int>(s.marths.files.K_ref.rows()), 2, 3};
  if (s.structure.mode == models::StructureMode::kPredefined) return {};
  return {static_cast<int>(models::StructureFromScenario(s.structure).M.rows()), 0, 0};
}
}  // namespace

std::int64_t LogBytesPerStepOf(const scenario::Scenario& s) {
  const ArraySizes a = ArraySizesOf(s);
  return LogBytesPerStep(a.n_dof, a.n_act, a.n_iface);
}

OutputBytes EstimateOutputBytes(const scenario::Scenario& s) {
  const ArraySizes a = ArraySizesOf(s);
  const double steps = static_cast<double>(s.steps());
  const double log_step = static_cast<double>(LogBytesPerStep(a.n_dof, a.n_act, a.n_iface));
  const double row = static_cast<double>(StoredBytesPerStep(a.n_dof, a.n_act, a.n_iface)) - log_step;
  OutputBytes b;
  b.log = steps * log_step;
  b.csv = s.run.csv_every > 0 ? std::ceil(steps / s.run.csv_every) * row : 0.0;
  return b;
}

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir, lockstep::Faults faults,
                                                       const lockstep::Wiring& wiring) {
  if (s.marths.enabled) {  // the benchmark's two-actuator loop (participants/marths_participants.h)
    if (role == "integrator") return std::make_unique<MarthsIntegrator>(s, id, lcm, wiring, std::move(faults));
    if (role == "controller") return std::make_unique<MarthsController>(s, id, lcm, wiring, std::move(faults));
    if (role == "plant") return std::make_unique<MarthsPlant>(s, id, lcm, wiring, std::move(faults));
  }
  if (role == "integrator") return std::make_unique<Integrator>(s, id, lcm, wiring, std::move(faults));
  if (role == "controller") return std::make_unique<Controller>(s, id, lcm, wiring, std::move(faults));
  if (role == "plant") return std::make_unique<Plant>(s, id, lcm, wiring, std::move(faults));
  if (role == "semiactive") return std::make_unique<Semiactive>(s, id, lcm, wiring, std::move(faults));
  if (role == "logger") {
    return std::make_unique<Logger>(id, LockstepOf(s), lcm, wiring, out_dir + "/log.lcm", out_dir + "/signals.csv",
                                    std::move(faults), s.run.csv_every, s.realtime.enabled);
  }
  throw Error("", fmt::format("unknown participant role '{}'", role));
}

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir, lockstep::Faults faults) {
  return MakeParticipant(role, s, id, lcm, out_dir, std::move(faults), WiringOf(s));
}

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role, const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id, lcm::LCM* lcm,
                                                       const std::string& out_dir) {
  return MakeParticipant(role, s, id, lcm, out_dir, FaultsOf(s, role));
}

void CheckBuildable(const scenario::Scenario& s) {
  const lockstep::Wiring wiring = WiringOf(s);
  for (const lockstep::ResolvedRole& r : wiring.roles()) {
    if (r.row->acks_barrier) continue;  // the logger: it would create the run's files
    MakeParticipant(r.role(), s, IdentityOf(s, 1), nullptr, "", {}, wiring);
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

/// Follow mode's default socket receive buffer [bytes]: the kernel doubles it for its bookkeeping,
/// ~8000 small datagrams, over 1 s of a 2 kHz feed. Capped by net.core.rmem_max.
constexpr int kFollowRecvBufBytes = 4 << 20;

/// The command line of a participant process.
struct RoleArgs {
  std::string scenario_path, url, out_dir = ".";
  std::int64_t run_id = 0;
  double handshake_timeout_s = 0;
  bool follow = false;
  lockstep::FollowOptions follow_options;
  /// Follow mode: the socket receive buffer to ask for [bytes] (LCM's recv_buf_size), 0: the OS's.
  int follow_recv_buf_bytes = kFollowRecvBufBytes;
  bool realtime = false;
  double heartbeat_s = 0;
};

/// Parses the command line of procs/<role>; -1 to go on, else the code to exit with.
int ParseRoleArgs(const std::string& name, int argc, char** argv, RoleArgs* a) {
  CLI::App app{fmt::format("rths-{}: the {} participant of a lockstep run (started by `rths run`)", name, name)};
  app.add_option("--scenario", a->scenario_path, "scenario TOML file")->required();
  app.add_option("--lcm-url", a->url, "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0")->required();
  app.add_option("--run-id", a->run_id, "run id shared by every participant")->required();
  app.add_option("--out", a->out_dir, "output folder (the logger's files; logs/<role>.json for everyone)");
  app.add_option("--handshake-timeout-s", a->handshake_timeout_s,
                 "wait this long for the handshake instead of the scenario's lockstep.handshake_timeout_s "
                 "(rths run --external: time for the external participants to join) [s]")
      ->check(CLI::Range(0.1, 86400.0));
  app.add_option("--heartbeat-s", a->heartbeat_s,
                 "send a HEARTBEAT every S seconds from HELLO on, so that the clock notices within 5 S if this "
                 "process goes (for a participant on another host, whose pid the clock cannot watch; "
                 "docs/participant.md, Liveness) [s]")
      ->check(CLI::Range(0.01, 60.0));
  app.add_flag("--follow", a->follow,
               "follow mode: no handshake, no clock; answer each step as soon as its inputs arrive (fed by "
               "lcm-logplayer from a recorded log, with that log's --run-id; docs/replay.md). A lost input is "
               "held at the one before it; at the end it prints how many steps it answered exactly, and exits 11 "
               "if not all");
  app.add_option("--follow-idle-s", a->follow_options.idle_exit_s,
                 "follow mode: finish after this long without a message [s]")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--follow-start-s", a->follow_options.start_wait_s,
                 "follow mode: wait this long for the first message (time to start lcm-logplayer) [s]")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--follow-queue", a->follow_options.queue_capacity,
                 "follow mode: messages LCM may queue per channel before it drops one (LCM's own default: 30)")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  app.add_option("--follow-recv-buf", a->follow_recv_buf_bytes,
                 "follow mode: socket receive buffer to ask for [bytes], capped by net.core.rmem_max; 0: the "
                 "system's default; ignored if the URL gives recv_buf_size")
      ->check(CLI::Range(0, 1 << 30))
      ->capture_default_str();
  app.add_flag("--realtime", a->realtime, "real-time paced mode, as if the scenario said [realtime] enabled = true");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : rths::kExitUsage;
  }
  return -1;
}

/// Follow mode: says what the participant did with the feed (stdout) and exits kExitFollowInexact
/// if a step was not answered exactly.
void JudgeFollow(const RoleArgs& a, Outcome* o) {
  if (o->follow.is_null()) return;
  const nlohmann::json& f = o->follow;
  const auto n = f.at("n_steps").get<std::int64_t>();
  const auto exact = f.at("exact").get<std::int64_t>();
  std::printf("rths-%s: follow: run %lld, %lld steps: %lld exact, %lld held, %lld resumed after a hold, %lld unseen "
              "(%s)\n",
              o->role.c_str(), static_cast<long long>(a.run_id), static_cast<long long>(n),
              static_cast<long long>(exact), static_cast<long long>(f.at("held").get<std::int64_t>()),
              static_cast<long long>(f.at("resumed").get<std::int64_t>()),
              static_cast<long long>(f.at("unseen").get<std::int64_t>()), OutcomePath(a.out_dir, o->role).c_str());
  std::fflush(stdout);
  if (o->exit_code != 0 || exact == n) return;
  o->exit_code = rths::kExitFollowInexact;
  if (f.at("messages").get<std::int64_t>() == 0) {
    o->message = fmt::format("follow: heard nothing of run {} on {} (is lcm-logplayer playing that run's log on "
                             "this URL, with this --run-id?)",
                             a.run_id, a.url);
  } else {
    o->message = fmt::format("follow: {} of {} steps answered exactly (the others are listed in {}; docs/replay.md)",
                             exact, n, OutcomePath(a.out_dir, o->role));
  }
}

/// Follow mode: the URL with a socket receive buffer (LCM's recv_buf_size) unless it names one,
/// no larger than the kernel allows (`rmem_max_bytes`, net.core.rmem_max; 0 if unknown), so that
/// LCM does not warn; a note on stderr if the kernel allows less than asked.
std::string FollowUrl(const std::string& url, int want_bytes, long long rmem_max_bytes, const std::string& role) {
  if (want_bytes <= 0 || url.find("recv_buf_size=") != std::string::npos) return url;
  long long bytes = want_bytes;
  if (rmem_max_bytes > 0 && rmem_max_bytes < bytes) {
    std::fprintf(stderr,
                 "rths-%s: follow: the kernel allows a socket receive buffer of %lld bytes (net.core.rmem_max), "
                 "%d asked; a burst of the feed may be lost (as root: sysctl -w net.core.rmem_max=%d)\n",
                 role.c_str(), rmem_max_bytes, want_bytes, want_bytes);
    bytes = rmem_max_bytes;
  }
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=" + std::to_string(bytes);
}

/// net.core.rmem_max [bytes], 0 if it cannot be read.
long long ReadRmemMax() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  long long v = 0;
  return (in >> v) ? v : 0;
}

/// Follow mode if asked, then the event loop on the participant's transport; its outcome in `*o`.
template <class Transport>
void RunParticipant(const RoleArgs& a, lockstep::Participant* p, Transport* transport, Outcome* o) {
  if (a.follow) p->Follow(a.follow_options);
  const int rc = lockstep::RunLoop(transport, {p}, &g_stop);
  *o = OutcomeOf(*p, *o);
  if (o->exit_code == 0) o->exit_code = rc;  // e.g. the receive failed
  if (a.follow) JudgeFollow(a, o);
}

}  // namespace

std::string MulticastRouteAdvice() {
  const std::string hint = lockstep::CheckMulticastRoute();
  return hint.empty() ? hint : hint + "\nor run in one process instead:  ./rths run --transport memq";
}

namespace {

/// Builds the participant on the transport of `a.url` (our udpm sockets: a port per channel, then
/// this process receives only its channels, or the run's one port; else one LCM instance) and runs it.
void RunOnTransport(std::string_view role, const scenario::Scenario& s, const RoleArgs& a, Outcome* o) {
  auto more = [] {  // how to fix the host, if that is the reason
    const std::string hint = MulticastRouteAdvice();
    return hint.empty() ? hint : "\n" + hint;
  };
  const std::string url =
      a.follow ? FollowUrl(a.url, a.follow_recv_buf_bytes, ReadRmemMax(), std::string(role)) : a.url;
  // The clock of a participant process publishes its live records for a monitor on the URL.
  auto make = [&](lcm::LCM* lcm) {
    auto p = MakeParticipant(role, s, IdentityOf(s, a.run_id), lcm, a.out_dir);
    if (auto* clock = dynamic_cast<lockstep::ClockParticipant*>(p.get())) clock->PublishLive();
    return p;
  };
  // A udpm URL is read with our own sockets (a port per channel, or the run's one port), in this
  // thread; LCM's instance (its receive thread and notify pipe) only for other URLs, a follower's
  // and URLs with options only LCM knows.
  const std::optional<lockstep::UdpmUrl> udpm = lockstep::UdpmUrl::Parse(a.url);
  if (udpm && !a.follow && udpm->other_options.empty()) {
    lockstep::UdpmChannels channels(*udpm);
    auto p = make(nullptr);
    std::string why = channels.error();
    if (why.empty()) {
      try {
        p->Attach(&channels);
      } catch (const std::runtime_error& e) {
        why = e.what();
      }
    }
    if (why.empty()) return RunParticipant(a, p.get(), static_cast<lockstep::Channels*>(&channels), o);
    o->exit_code = rths::kExitLockstep;
    o->message = fmt::format("cannot open the channels of {}: {}{}", a.url, why, more());
  } else if (lcm::LCM lcm(url); !lcm.good()) {
    o->exit_code = rths::kExitLockstep;
    o->message = fmt::format("cannot open LCM at {}{}", url, more());
  } else {
    RunParticipant(a, make(&lcm).get(), &lcm, o);
  }
}
}  // namespace

int RoleMain(std::string_view role, int argc, char** argv) {
  const std::string name(role);
  RoleArgs a;
  if (const int code = ParseRoleArgs(name, argc, argv, &a); code >= 0) return code;
  if (a.follow && (role == lockstep::kClockRole || role == "logger")) {
    std::fprintf(stderr, "rths-%s: --follow: %s\n", name.c_str(),
                 role == "logger" ? "the logger records a lockstep run; record a replay with lcm-logger"
                                  : "the integrator is the clock: it cannot follow");
    return rths::kExitUsage;
  }
  // A file grown past RLIMIT_FSIZE must fail the write (EFBIG), not kill the process.
  std::signal(SIGXFSZ, SIG_IGN);
  // SIGTERM (the supervisor's teardown) or SIGINT (Ctrl-C reaches the whole process group): stop
  // at once, committed output flushed, and say so in the outcome.
  std::signal(SIGTERM, OnStopSignal);
  std::signal(SIGINT, OnStopSignal);
  Outcome o;
  o.role = name;
  // A follow-mode process is started by hand: its outcome folder may not exist yet.
  if (a.follow) {
    std::error_code ec;
    fs::create_directories(fs::path(OutcomePath(a.out_dir, name)).parent_path(), ec);
  }
  io::ReserveFile(OutcomePath(a.out_dir, name), kOutcomeReserve, "{}\n");
  try {
    scenario::Scenario s = scenario::LoadScenario(a.scenario_path);
    // Not part of the handshake's identity (the hash is of the file): only how long to wait.
    if (a.handshake_timeout_s > 0) s.lockstep.handshake_timeout_s = a.handshake_timeout_s;
    if (a.realtime) s.realtime.enabled = true;  // pacing is not part of the identity either
    // Liveness (not part of the identity): our pid means something to the clock only on its host,
    // which a ttl=0 URL guarantees.
    const auto url = lockstep::UdpmUrl::Parse(a.url);
    s.lockstep.announce_pid = url && url->ttl == 0;
    s.lockstep.heartbeat_s = a.heartbeat_s;
    if (s.realtime.enabled) {
      o.realtime_setup = lockstep::EnterRealtime(s.realtime);
      if (!o.realtime_setup.note.empty()) std::fprintf(stderr, "%s: %s\n", name.c_str(), o.realtime_setup.note.c_str());
    }
    RunOnTransport(role, s, a, &o);
  } catch (const Error& e) {
    o.exit_code = rths::kExitUsage;
    o.message = e.what();
  } catch (const std::exception& e) {
    o.exit_code = rths::kExitInternal;
    o.message = fmt::format("internal error: {}", e.what());
  }
  if (o.exit_code != 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), o.message.c_str());
  io::OverwriteFile(OutcomePath(a.out_dir, name), OutcomeToJson(o).dump(2) + "\n");
  return o.exit_code;
}

}  // namespace rths::participants
