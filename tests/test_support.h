#pragma once
// Shared by the tests that run whole lockstep groups in this process (memq://).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "lockstep/runtime.h"
#include "participants/factory.h"
#include "scenario/scenario.h"

namespace rths_test {

namespace fs = std::filesystem;

/// A fresh, empty folder under the system's temp folder, unique to this test process.
inline fs::path TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("rths_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

inline fs::path WriteScenario(const fs::path& dir, const std::string& text) {
  const fs::path p = dir / "scenario.toml";
  std::ofstream(p) << text;
  return p;
}

struct MemqRun {
  int code = 0;
  std::vector<std::pair<std::string, int>> exit_codes;
  std::vector<std::string> errors;
};

/// Runs every participant in this process on memq://, like `rths run --transport memq`.
/// `per_role` holds one scenario for all, or one per role in the order of the loop below.
inline MemqRun RunMemq(const std::vector<rths::scenario::Scenario>& per_role, const fs::path& out,
                const std::string& fault_role = "", rths::lockstep::Faults faults = {}) {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  std::vector<std::unique_ptr<rths::lockstep::Participant>> owned;
  std::vector<rths::lockstep::Participant*> ps;
  int i = 0;
  for (std::string_view role : {"logger", "plant", "controller", "semiactive", "integrator"}) {
    const auto& s = per_role[per_role.size() == 1 ? 0 : i++];
    owned.push_back(rths::participants::MakeParticipant(
        role, s, rths::participants::IdentityOf(s, 42), &lcm, out.string()));
    if (role == fault_role) owned.back()->faults = faults;
    ps.push_back(owned.back().get());
  }
  MemqRun r;
  r.code = rths::lockstep::RunLoop(&lcm, ps);
  for (auto* p : ps) {
    r.exit_codes.emplace_back(p->name(), p->exit_code());
    r.errors.push_back(p->error());
  }
  return r;
}

}  // namespace rths_test
