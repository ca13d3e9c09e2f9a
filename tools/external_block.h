#pragma once
/// @file What `rths run --external` and `rths replay --external` share (docs/participant.md): the
/// list of external roles, checked, and the block printed for the user's participants.
/// Header-only; the tools include it, the libraries never do.
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "supervisor/request.h"

namespace rths::tools {

/// The roles of `--external ROLE[,ROLE...]`, checked (controller, plant, semiactive); throws a
/// message for the command line.
inline supervisor::ExternalRoles ParseExternalRoles(const std::string& list, double join_timeout_s) {
  supervisor::ExternalRoles external;
  std::stringstream ss(list);
  for (std::string role; std::getline(ss, role, ',');) {
    if (role.empty()) continue;
    if (role == "integrator" || role == "logger") {
      throw std::runtime_error(fmt::format(
          "--external {}: the {} cannot be external ({}); allowed: controller, plant, semiactive", role, role,
          role == "integrator" ? "it is the run's clock" : "the run's record must be written by rths"));
    }
    if (role != "controller" && role != "plant" && role != "semiactive") {
      throw std::runtime_error(
          fmt::format("--external {}: unknown role; allowed: controller, plant, semiactive", role));
    }
    if (!external.has(role)) external.roles.push_back(role);
  }
  external.join_timeout_s = join_timeout_s;
  return external;
}

/// Always printed (also with --quiet): what the user's participants need to join a run of
/// `steps` steps.
inline void PrintExternal(const supervisor::RunRequest& r, const supervisor::RunPlan& plan, std::int64_t steps) {
  const auto& s = plan.scenario;
  const std::string& url = plan.url;
  std::string roles;
  for (const auto& role : r.external.roles) roles += (roles.empty() ? "" : ",") + role;
  std::printf("external: %s\n", roles.c_str());
  std::printf("  lcm_url          %s\n", url.c_str());
  std::printf("  port             %s\n", url.substr(url.rfind(':') + 1, url.find('?') - url.rfind(':') - 1).c_str());
  std::printf("  run_id           %lld\n", static_cast<long long>(plan.run_id));
  std::printf("  scenario         %s%s\n", plan.scenario_path.c_str(),
              r.scenario_header.empty() ? ""
                                        : "  (the scenario with your --set overrides: give your participant this "
                                          "file; its hash is not the original's)");
  std::printf("  scenario_sha256  %s\n", s.sha256.c_str());
  std::printf("  steps            %lld of %g s each%s\n", static_cast<long long>(steps), s.run.dt_s,
              steps == s.steps() ? "" : "  (not the scenario's own count: give your participant this one)");
  std::printf("  built-in example %s/rths-%s --scenario %s --lcm-url '%s' --run-id %lld\n", r.bin_dir.c_str(),
              r.external.roles.front().c_str(), plan.scenario_path.c_str(), url.c_str(),
              static_cast<long long>(plan.run_id));
  std::printf("waiting up to %g s for %s to say HELLO (docs/participant.md)\n", r.external.join_timeout_s,
              roles.c_str());
  std::fflush(stdout);
}

}  // namespace rths::tools
