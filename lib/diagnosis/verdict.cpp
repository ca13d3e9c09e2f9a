#include "diagnosis/verdict.h"

#include <algorithm>

#include <fmt/format.h>

namespace rths::diagnosis {

using stages::ChannelState;
using stages::EffectResults;

void RankEffects(const std::vector<std::string>& verdict, EffectResults* er, std::size_t n_states, Result* res) {
  int pos = 0;
  for (const auto& n : verdict) {
    (*er)[n].order = pos++;
    res->effects.push_back((*er)[n]);
  }
  std::vector<EffectResult> rest;
  for (const auto& [n, e] : *er)
    if (e.order < 0) rest.push_back(e);
  std::sort(rest.begin(), rest.end(), [](const EffectResult& a, const EffectResult& b) { return a.shrink_pct > b.shrink_pct; });
  for (auto& e : rest) res->effects.push_back(e);
  for (std::size_t c = 0; c < n_states; ++c) {
    if (!res->channels[c].diagnosed) continue;
    EffectResult e;
    e.name = "sensor_noise";
    e.channel = res->channels[c].channel;
    e.params["rms"] = res->channels[c].noise_rms;
    e.test_nrmse_after = res->channels[c].gap_test_pct;
    e.train_nrmse_after = res->channels[c].gap_train_pct;
    e.shrink_pct = 0;
    res->effects.push_back(e);
  }
}

/// res->verdict: the retained effects in order; else "unknown" if a channel is structured, "none"
/// if not. A channel left unexplained beside retained effects is a warning.
void FormVerdict(const std::vector<std::string>& verdict, const std::vector<ChannelState>& st, Result* res) {
  bool any_structured = false;
  for (const auto& s : st) any_structured |= s.structured;
  if (!verdict.empty()) {
    res->verdict = verdict;
    for (const auto& cs : res->channels)
      if (cs.status == "unexplained")
        res->warnings.push_back(fmt::format("channel {}: a structured residual remains that no candidate explains", cs.channel));
  } else {
    res->verdict = {any_structured ? "unknown" : "none"};
  }
}

}  // namespace rths::diagnosis
