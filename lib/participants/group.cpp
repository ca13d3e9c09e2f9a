#include "participants/group.h"

#include <memory>

#include "core/error.h"
#include "participants/factory.h"

namespace rths::participants {

std::vector<Outcome> RunGroupInProcess(const std::vector<scenario::Scenario>& per_role,
                                       std::int64_t run_id, const std::string& out_dir,
                                       const std::vector<RoleFault>& faults) {
  if (per_role.size() != 1 && per_role.size() != std::size(kGroupOrder)) {
    throw Error("RunGroupInProcess", "give one scenario, or one per role");
  }
  lcm::LCM lcm("memq://");
  if (!lcm.good()) throw Error("RunGroupInProcess", "cannot create a memq:// LCM instance");
  std::vector<std::unique_ptr<lockstep::Participant>> owned;
  std::vector<lockstep::Participant*> group;
  for (std::size_t i = 0; i < std::size(kGroupOrder); ++i) {
    const auto& s = per_role[per_role.size() == 1 ? 0 : i];
    owned.push_back(MakeParticipant(kGroupOrder[i], s, IdentityOf(s, run_id), &lcm, out_dir));
    for (const auto& f : faults) {
      if (f.role == kGroupOrder[i]) owned.back()->faults = f.faults;
    }
    group.push_back(owned.back().get());
  }
  lockstep::RunLoop(&lcm, group);
  std::vector<Outcome> outcomes;
  for (const auto* p : group) outcomes.push_back({p->name(), p->exit_code(), 0, p->error()});
  return outcomes;
}

const Outcome* RootCause(const std::vector<Outcome>& outcomes) {
  auto blame = [](const Outcome& o) {
    if (o.signal != 0) return 4;
    switch (o.exit_code) {
      case lockstep::kExitOk: return 0;
      case lockstep::kExitPeerAbort: return 1;
      case lockstep::kExitLockstep: return 2;
      default: return 3;
    }
  };
  const Outcome* worst = nullptr;
  for (const auto& o : outcomes) {
    if (blame(o) > 0 && (!worst || blame(o) > blame(*worst))) worst = &o;
  }
  return worst;
}

}  // namespace rths::participants
