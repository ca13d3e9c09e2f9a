#include "participants/factory.h"

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "core/error.h"
#include "participants/controller.h"
#include "participants/integrator.h"
#include "participants/logger.h"
#include "participants/plant.h"
#include "participants/semiactive.h"

namespace rths::participants {

lockstep::RunIdentity IdentityOf(const scenario::Scenario& s, std::int64_t run_id) {
  return {run_id, s.sha256, s.steps(), s.run.dt_s};
}

lockstep::Timing TimingOf(const scenario::Scenario& s) {
  return {s.lockstep.timeout_ms, s.lockstep.max_attempts, s.lockstep.handshake_timeout_s};
}

std::unique_ptr<lockstep::Participant> MakeParticipant(std::string_view role,
                                                       const scenario::Scenario& s,
                                                       const lockstep::RunIdentity& id,
                                                       lcm::LCM* lcm, const std::string& out_dir) {
  if (role == "integrator") return std::make_unique<Integrator>(s, id, lcm);
  if (role == "controller") return std::make_unique<Controller>(s, id, lcm);
  if (role == "plant") return std::make_unique<Plant>(s, id, lcm);
  if (role == "semiactive") return std::make_unique<Semiactive>(s, id, lcm);
  if (role == "logger") {
    return std::make_unique<Logger>(id, TimingOf(s), lcm, out_dir + "/log.lcm",
                                    out_dir + "/signals.csv");
  }
  throw Error("", fmt::format("unknown participant role '{}'", role));
}

void CheckBuildable(const scenario::Scenario& s) {
  lcm::LCM lcm("memq://");
  for (std::string_view role : {"integrator", "controller", "plant", "semiactive"}) {
    MakeParticipant(role, s, IdentityOf(s, 1), &lcm, "");
  }
}

int RoleMain(std::string_view role, int argc, char** argv) {
  const std::string name(role);
  CLI::App app{fmt::format("rths-{}: the {} participant of a lockstep run (started by `rths run`)",
                           name, name)};
  std::string scenario_path, url, out_dir = ".";
  std::int64_t run_id = 0;
  lockstep::Faults faults;
  app.add_option("--scenario", scenario_path, "scenario TOML file")->required();
  app.add_option("--lcm-url", url, "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0")->required();
  app.add_option("--run-id", run_id, "run id shared by every participant")->required();
  app.add_option("--out", out_dir, "output folder (logger)");
  app.add_option("--fault-drop", faults.drop_first_request_at, "test only: lose request k once")
      ->group("");
  app.add_option("--fault-stall", faults.stall_at, "test only: stop answering at step k")->group("");
  app.add_option("--fault-throw", faults.throw_at, "test only: throw at step k")->group("");
  app.add_option("--fault-crash", faults.crash_at, "test only: abort() at step k")->group("");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : lockstep::kExitUsage;
  }
  try {
    const scenario::Scenario s = scenario::LoadScenario(scenario_path);
    lcm::LCM lcm(url);
    if (!lcm.good()) {
      std::string hint = lockstep::CheckMulticastRoute();
      std::fprintf(stderr, "%s: cannot open LCM at %s\n%s\n", name.c_str(), url.c_str(),
                   hint.c_str());
      return lockstep::kExitLockstep;
    }
    auto p = MakeParticipant(role, s, IdentityOf(s, run_id), &lcm, out_dir);
    p->faults = faults;
    const int code = lockstep::RunLoop(&lcm, {p.get()});
    if (code != 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), p->error().c_str());
    return code;
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", name.c_str(), e.what());
    return lockstep::kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", name.c_str(), e.what());
    return lockstep::kExitInternal;
  }
}

}  // namespace rths::participants
