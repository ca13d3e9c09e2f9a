#include "lockstep/wiring.h"

#include <algorithm>
#include <bit>

#include <fmt/core.h>

#include "core/error.h"

namespace rths::lockstep {

namespace {
/// The window of steps the dependency check looks at, around step 0: earlier messages are taken
/// as there, later ones mean a role waits on the future of the future.
constexpr int kWindow = 3;
constexpr int kSteps = 2 * kWindow + 1;
static_assert(kRosterSize * kSteps <= 64, "ancestor sets are 64-bit masks");

void AddWait(ResolvedRole* r, StepInput in) {
  for (int i = 0; i < r->n_waits; ++i) {
    if (r->waits[i].channel == in.channel && r->waits[i].offset == in.offset) return;
  }
  if (r->n_waits == static_cast<int>(r->waits.size())) {
    throw Error("lockstep wiring", fmt::format("{} waits for more than {} messages", r->role(), r->waits.size()));
  }
  r->waits[r->n_waits++] = in;
}

/// The dependency graph of one run: node (role, step s), s in [-kWindow, kWindow].
class Graph {
 public:
  Graph(const std::array<ResolvedRole, kRosterSize>& roles, const std::array<int, kChannelCodes>& owner)
      : roles_(roles), owner_(owner) {}

  /// The messages (role, s) follows from, as a mask of nodes; throws on a cycle.
  std::uint64_t Ancestors(int role, int s) {
    const int node = role * kSteps + s + kWindow;
    if (state_[node] == kDone) return anc_[node];
    if (state_[node] == kOpen) {
      throw Error("lockstep wiring", fmt::format("{}'s answer of step k depends on itself (a cycle)", roles_[role].role()));
    }
    state_[node] = kOpen;
    std::uint64_t mask = 0;
    const ResolvedRole& r = roles_[role];
    for (int i = 0; i < r.n_waits; ++i) {
      const int t = s + r.waits[i].offset;
      if (t < -kWindow) continue;  // long done
      if (t > kWindow) {
        throw Error("lockstep wiring", fmt::format("{} waits for messages more than {} steps ahead", r.role(), kWindow));
      }
      const int from = owner_[r.waits[i].channel];
      mask |= (std::uint64_t{1} << (from * kSteps + t + kWindow)) | Ancestors(from, t);
    }
    state_[node] = kDone;
    anc_[node] = mask;
    return mask;
  }
  static std::uint64_t Bit(int role, int s) { return std::uint64_t{1} << (role * kSteps + s + kWindow); }

 private:
  enum State : std::uint8_t { kNew, kOpen, kDone };
  const std::array<ResolvedRole, kRosterSize>& roles_;
  const std::array<int, kChannelCodes>& owner_;
  std::array<State, kRosterSize * kSteps> state_{};
  std::array<std::uint64_t, kRosterSize * kSteps> anc_{};
};

const RoleRow& RowOf(std::string_view role, std::string_view variant) {
  for (const RoleRow& row : kStepTable) {
    if (row.role == role && row.variant == variant) return row;
  }
  throw Error("lockstep wiring", fmt::format("no row for {} \"{}\" in the step table", role, variant));
}
}  // namespace

const char* MessageName(Channel channel) {
  switch (channel) {
    case kDesired: return "desired_t";
    case kCommand: return "command_t";
    case kMeasured: return "measured_t";
    case kCurrent: return "current_t";
    case kAck: return "ack_t";
    default: return "";
  }
}

int ResolvedRole::max_barrier_offset() const {
  int m = 0;
  for (int i = 0; i < row->n_barrier; ++i) m = std::max(m, row->barrier[i]);
  return m;
}

bool ResolvedRole::Waits(Channel channel, std::int64_t j, std::int64_t k) const {
  for (int i = 0; i < n_waits; ++i) {
    if (waits[i].channel == channel && k + waits[i].offset == j) return true;
  }
  return false;
}

Wiring Wiring::Resolve(const std::vector<RoleVariant>& variants) {
  Wiring w;
  for (const RoleVariant& v : variants) {
    if (RosterIndex(v.role) < 0) throw Error("lockstep wiring", fmt::format("unknown role '{}'", v.role));
  }
  std::array<int, kChannelCodes> owner;
  owner.fill(-1);
  for (int i = 0; i < kRosterSize; ++i) {
    std::string_view variant;
    for (const RoleVariant& v : variants) {
      if (v.role == kRoster[i]) variant = v.variant;
    }
    w.roles_[i].row = &RowOf(kRoster[i], variant);
    const Channel answer = w.roles_[i].row->answer;
    if (owner[answer] >= 0) {
      throw Error("lockstep wiring", fmt::format("{} and {} both answer on {}", kRoster[owner[answer]], kRoster[i],
                                                 ChannelName(answer)));
    }
    owner[answer] = i;
  }
  for (ResolvedRole& r : w.roles_) {
    for (int i = 0; i < r.row->n_inputs(); ++i) AddWait(&r, r.row->inputs[i]);
    for (const ResolvedRole& other : w.roles_) {  // the barrier: the clock's of step k-1, the logger's of k
      if (&other == &r || other.row->clock || !(r.row->clock || r.row->acks_barrier)) continue;
      for (int b = 0; b < other.row->n_barrier; ++b) {
        AddWait(&r, {other.row->answer, other.row->barrier[b] - (r.row->clock ? 1 : 0)});
      }
    }
    for (int i = 0; i < r.n_waits; ++i) {
      const StepInput in = r.waits[i];
      if (in.channel <= kNoChannel || in.channel >= kChannelCodes || owner[in.channel] < 0) {
        throw Error("lockstep wiring", fmt::format("{} waits for channel {}, which no role answers", r.role(),
                                                   static_cast<int>(in.channel)));
      }
      r.reads[in.channel] = true;
    }
  }
  Graph g(w.roles_, owner);
  std::array<int, kRosterSize> weight{};
  for (int i = 0; i < kRosterSize; ++i) {
    ResolvedRole& r = w.roles_[i];
    weight[i] = std::popcount(g.Ancestors(i, 0));
    r.wake.fill(Wake::kLater);
    bool wakes = false;
    for (int a = 0; a < r.n_waits; ++a) {
      const std::uint64_t bit = Graph::Bit(owner[r.waits[a].channel], r.waits[a].offset);
      bool follows = false;  // another input of the same step follows from this one
      for (int b = 0; b < r.n_waits && !follows; ++b) {
        if (b != a) follows = (g.Ancestors(owner[r.waits[b].channel], r.waits[b].offset) & bit) != 0;
      }
      if (!follows) {
        r.wakes_for[a] = true;
        r.wake[r.waits[a].channel] = Wake::kOnArrival;
        wakes = true;
      }
    }
    if (!wakes && !r.row->clock) throw Error("lockstep wiring", fmt::format("{} has no input to wake it", r.role()));
  }
  int n = 0;
  for (int i = 0; i < kRosterSize; ++i) {
    if (!w.roles_[i].row->clock) w.step_order_[n++] = i;
  }
  std::stable_sort(w.step_order_.begin(), w.step_order_.end(), [&](int a, int b) { return weight[a] < weight[b]; });
  return w;
}

const ResolvedRole& Wiring::Of(std::string_view role) const {
  const int i = RosterIndex(role);
  if (i < 0) throw Error("lockstep wiring", fmt::format("unknown role '{}'", role));
  return roles_[i];
}

std::string Wiring::Describe() const {
  auto at = [](StepInput in) {
    return fmt::format("{} k{}", MessageName(in.channel),
                       in.offset == 0 ? std::string() : fmt::format("{:+d}", in.offset));
  };
  std::string out;
  for (const ResolvedRole& r : roles_) {
    std::string waits, wakes, barrier;
    for (int i = 0; i < r.n_waits; ++i) {
      waits += (i ? ", " : "") + at(r.waits[i]);
      if (r.wakes_for[i]) wakes += (wakes.empty() ? "" : ", ") + at(r.waits[i]);
    }
    for (int b = 0; b < r.row->n_barrier; ++b) barrier += (b ? ", " : "") + at({r.row->answer, r.row->barrier[b]});
    out += fmt::format("{}: {} k <- {}; wakes for {}; barrier {}\n", r.role(), MessageName(r.row->answer), waits,
                       wakes.empty() ? "-" : wakes, barrier.empty() ? "-" : barrier);
  }
  return out;
}

}  // namespace rths::lockstep
