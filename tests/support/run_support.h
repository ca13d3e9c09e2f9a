#pragma once
// Runs whole lockstep groups in this process (memq://); links rths_participants.
#include <string>
#include <utility>
#include <vector>

#include "lockstep/faults.h"
#include "participants/group.h"
#include "scenario/scenario.h"

#include "test_support.h"

namespace rths_test {

struct MemqRun {
  int code = 0;
  std::vector<std::pair<std::string, int>> exit_codes;
  std::vector<std::string> errors;
};

/// Runs every participant in this process on memq://, like `rths run --transport memq`.
/// `per_role` holds one scenario for all, or one per role in lockstep::kBuildOrder.
inline MemqRun RunMemq(const std::vector<rths::scenario::Scenario>& per_role, const fs::path& out,
                       const std::string& fault_role = "", rths::lockstep::Faults faults = {}) {
  std::vector<rths::participants::RoleFault> f;
  if (!fault_role.empty()) f.push_back({fault_role, faults});
  const auto outcomes = rths::participants::RunGroupInProcess(per_role, 42, out.string(), f);
  MemqRun r;
  const auto* culprit = rths::participants::RootCause(outcomes);
  r.code = culprit ? culprit->exit_code : 0;
  for (const auto& o : outcomes) {
    r.exit_codes.emplace_back(o.role, o.exit_code);
    r.errors.push_back(o.message);
  }
  return r;
}

}  // namespace rths_test
