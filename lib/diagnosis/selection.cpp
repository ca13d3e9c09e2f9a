#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "diagnosis/candidates.h"
#include "diagnosis/fit.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis::stages {

std::vector<EffectResult::Alternative> CloseCalls(const std::map<std::string, Trial>& trials, const Trial& best,
                                                  double n_eff, const std::vector<CandidateSpec>& specs,
                                                  std::size_t records) {
  std::vector<EffectResult::Alternative> alts;
  const int p_best = FreeParams(SpecOf(specs, best.name), records);
  for (const auto& [name, t] : trials) {
    if (name == best.name || !t.pass) continue;
    const int p = FreeParams(SpecOf(specs, name), records);
    const double d = n_eff * std::log(std::max(t.sse, 1e-300) / std::max(best.sse, 1e-300)) + (p - p_best) * std::log(n_eff);
    if (d < tuning::kCloseCallBic) alts.push_back({name, std::max(0.0, d), ParamMap(specs, name, t.params.at(name))});
  }
  std::sort(alts.begin(), alts.end(), [](const auto& a, const auto& b) { return a.delta_bic < b.delta_bic; });
  return alts;
}

void SelectEffects(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o) {
  ChannelState& s = *sp;
  const double dt = s.train.recs().front().dt;
  for (;;) {
    std::optional<Trial> best;
    const double tau = IntegratedCorrelationTime(s.train, s.pred_train);
    const double n_eff = std::max(1.0, static_cast<double>(s.n_train) / tau);
    const double excess = s.sse - static_cast<double>(s.n_train) * s.var_floor;
    // Only a channel whose current residual is still above its floor gets another effect.
    const bool still_structured = s.sse > o.none_ratio * static_cast<double>(s.n_train) * s.var_floor;
    for (const auto& spec : specs) {
      if (spec.channel != s.ch || s.sel.count(spec.name)) continue;
      Trial t;
      t.name = spec.name;
      t.params = s.sel;
      double sse = FitEffect(s.train, specs, &t.params, spec.name, o);
      sse = RefitAll(s.train, specs, &t.params, sse, tuning::kTrialRefitRounds, o);  // joint refit
      t.sse = sse;
      const int p = FreeParams(spec, s.train.recs().size());
      t.dbic = n_eff * std::log(std::max(sse, 1e-300) / std::max(s.sse, 1e-300)) + p * std::log(n_eff);
      t.excess_red = excess > 0 ? (s.sse - sse) / excess : 0.0;
      // The candidate's own share: the trial's set without it (the others as refitted).
      Params without = t.params;
      without.erase(spec.name);
      const double sse_wo = s.train.Sse(s.train.Predict(ToSet(specs, without)));
      const double excess_wo = sse_wo - static_cast<double>(s.n_train) * s.var_floor;
      t.marginal_red = excess_wo > 0 ? (sse_wo - sse) / excess_wo : 0.0;
      t.pass = s.structured && still_structured && t.dbic < 0 && t.excess_red >= o.min_excess_reduction &&
               t.marginal_red >= o.min_excess_reduction &&
               (sse_wo - sse) >= o.min_floor_gain * static_cast<double>(s.n_train) * s.var_floor &&
               static_cast<int>(s.order.size()) < tuning::kMaxEffectsPerChannel &&
               !AtBound(spec, t.params.at(spec.name)) && FormOf(spec, t.params.at(spec.name)).empty() &&
               !(spec.name == "pure_delay" && SubSampleDelayBeside(t.params, dt, o)) && !SkewTooShort(s, t.params);
      s.last_trial[spec.name] = t;
      if (t.pass && (!best || t.excess_red > best->excess_red)) best = t;
    }
    if (!best) break;
    s.alternatives[best->name] = CloseCalls(s.last_trial, *best, n_eff, specs, s.train.recs().size());
    Params p = best->params;
    RefitAll(s.train, specs, &p, best->sse, o.refit_rounds, o);
    AddEffect(&s, specs, best->name, std::move(p), best->excess_red, best->dbic);
  }
}

void AddEffect(ChannelState* sp, const std::vector<CandidateSpec>& specs, const std::string& name, Params set,
               double excess_red, double dbic) {
  ChannelState& s = *sp;
  s.sel = std::move(set);
  s.order.push_back(name);
  s.sel_stats[name] = {excess_red, dbic};
  s.pred_train = s.train.Predict(ToSet(specs, s.sel));
  s.sse = s.train.Sse(s.pred_train);
  s.last_trial.erase(name);
}

void SwapEffects(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                 std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  // E.g. a fast oil-column mode standing in for a delay.
  for (int sw = 0; sw < o.swap_passes && !s.order.empty(); ++sw) {
    double best_sse = s.sse * (1.0 - tuning::kSwapMinGain);
    std::optional<std::pair<std::size_t, Params>> swap;
    std::string swap_in;
    for (std::size_t j = 0; j < s.order.size(); ++j) {
      for (const auto& spec : specs) {
        if (spec.channel != s.ch || s.sel.count(spec.name)) continue;
        Params q = s.sel;
        q.erase(s.order[j]);
        double sq = FitEffect(s.train, specs, &q, spec.name, o);
        sq = RefitAll(s.train, specs, &q, sq, o.refit_rounds, o);
        if (AtBound(spec, q.at(spec.name)) || !FormOf(spec, q.at(spec.name)).empty() || SkewTooShort(s, q))
          continue;  // not an explanation
        if (sq < best_sse) best_sse = sq, swap = std::make_pair(j, q), swap_in = spec.name;
      }
    }
    if (!swap) break;
    warnings->push_back(fmt::format("channel {}: {} replaced by {} (training SSE {:.4g} -> {:.4g})", s.summary.channel,
                                    s.order[swap->first], swap_in, s.sse, best_sse));
    s.sel_stats[swap_in] = s.sel_stats[s.order[swap->first]];
    s.alternatives.erase(s.order[swap->first]);  // those were the replaced effect's
    s.order[swap->first] = swap_in;
    s.sel = swap->second;
    s.sse = best_sse;
  }
}

void PruneEffects(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                  std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  // A delay that the refits shrank below a sample beside another effect is that effect's form
  // mismatch, not a delay (SubSampleDelayBeside): removed, the rest refitted.
  if (SubSampleDelayBeside(s.sel, s.train.recs().front().dt, o)) {
    warnings->push_back(fmt::format("channel {}: pure_delay of {:.3g} ms beside {} removed (shorter than {:g} sample: a "
                                    "form or timing mismatch of the other effect, not a delay)",
                                    s.summary.channel, s.sel.at("pure_delay")[0], s.order.size() - 1, o.min_delay_samples));
    s.sel.erase("pure_delay");
    s.order.erase(std::find(s.order.begin(), s.order.end(), "pure_delay"));
    s.sse = RefitAll(s.train, specs, &s.sel, s.train.Sse(s.train.Predict(ToSet(specs, s.sel))), o.refit_rounds, o);
  }
  for (bool pruned = true; pruned && s.order.size() > 1;) {
    pruned = false;
    double least = o.min_excess_reduction;
    std::optional<std::pair<std::size_t, Params>> drop;
    double drop_sse = 0;
    for (std::size_t j = 0; j < s.order.size(); ++j) {
      Params q = s.sel;
      q.erase(s.order[j]);
      const double sq =
          RefitAll(s.train, specs, &q, s.train.Sse(s.train.Predict(ToSet(specs, q))), tuning::kPruneRefitRounds, o);
      const double ex = sq - static_cast<double>(s.n_train) * s.var_floor;
      const double share = ex > 0 ? (sq - s.sse) / ex : 0.0;
      if (share < least) least = share, drop = std::make_pair(j, q), drop_sse = sq;
    }
    if (drop) {
      warnings->push_back(fmt::format("channel {}: {} pruned (its own share of the excess {:.0f} % < {:.0f} %)",
                                      s.summary.channel, s.order[drop->first], 100.0 * least,
                                      100.0 * o.min_excess_reduction));
      s.order.erase(s.order.begin() + static_cast<std::ptrdiff_t>(drop->first));
      s.sel = drop->second;
      s.sse = drop_sse;
      pruned = true;
    }
  }
  s.pred_train = s.train.Predict(ToSet(specs, s.sel));
  s.sse = s.train.Sse(s.pred_train);
}

void RetainOnTest(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                  std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  // A fit of training misfit that does not carry over to the test records is not retained.
  const double before = s.summary.gap_test_pct;
  Params cum;
  double prev = before;
  std::vector<std::string> kept;
  for (const auto& name : s.order) {
    cum[name] = s.sel.at(name);
    const double after = s.test.NrmsePct(s.test.Sse(s.test.Predict(ToSet(specs, cum), nullptr, true)));
    if (after > prev * (1.0 + o.max_test_worsening)) {
      warnings->push_back(fmt::format("channel {}: {} (selected on the training records) raises the test NRMSE "
                                      "from {:.4g} % to {:.4g} %: not retained",
                                      s.summary.channel, name, prev, after));
      cum.erase(name);
    } else {
      kept.push_back(name);
      prev = after;
    }
  }
  if (kept.size() != s.order.size()) {
    Params q;
    for (const auto& n : kept) q[n] = s.sel.at(n);
    s.order = kept;
    s.sel = q;
    s.sse = RefitAll(s.train, specs, &s.sel, s.train.Sse(s.train.Predict(ToSet(specs, s.sel))), o.refit_rounds, o);
    s.pred_train = s.train.Predict(ToSet(specs, s.sel));
  }
}

}  // namespace rths::diagnosis::stages
