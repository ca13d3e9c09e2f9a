// SplitLostMotion and WeighLostMotion of stages.h: one lost-motion effect tried as two, two weighed
// against one (docs/diagnosis.md "Lost motion").
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "diagnosis/candidates.h"
#include "diagnosis/fit.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis::stages {

namespace {

constexpr const char* kLostMotion[] = {"backlash", "coulomb_friction", "presliding_friction", "command_dead_band"};

bool IsLostMotion(const std::string& name) {
  return std::find(std::begin(kLostMotion), std::end(kLostMotion), name) != std::end(kLostMotion);
}

/// The lost-motion effects among `order`, in its order.
std::vector<std::string> LostMotionEffects(const std::vector<std::string>& order) {
  std::vector<std::string> lost;
  for (const auto& n : order)
    if (IsLostMotion(n)) lost.push_back(n);
  return lost;
}

/// The motion an effect loses at a reversal, from each side [mm] (its half gap, loss or half width).
double LostMotionOf(const std::string& name, const std::vector<double>& v) {
  if (name == "backlash" || name == "command_dead_band") return 0.5 * v[0];
  return v[0];  // coulomb_friction's and presliding_friction's loss
}

/// `single`'s starting points from a lost motion L [mm], in its parameters' order.
std::vector<std::vector<double>> StartsFrom(const std::string& single, double L) {
  if (single == "presliding_friction") return {{L, 0.05 * L}, {L, 0.2 * L}, {L, 0.5 * L}};
  if (single == "coulomb_friction") return {{L}};
  return {{2.0 * L}};  // backlash's gap, command_dead_band's width
}

struct Candidate {
  std::string name;
  Params params;  // the whole set with it in the lost-motion effects' place
  double sse = std::numeric_limits<double>::infinity();
};

/// The candidate `name` of channel ch, or nullptr.
const CandidateSpec* ChannelSpec(const std::vector<CandidateSpec>& specs, const std::string& name, char ch) {
  for (const auto& c : specs)
    if (c.name == name && c.channel == ch) return &c;
  return nullptr;
}

/// The share of the excess `name` removes from the set p of training SSE sse: the set without it
/// refitted, (SSE_without - sse) / (SSE_without - n sigma^2) (the selection's marginal share).
double OwnShare(const ChannelState& s, const std::vector<CandidateSpec>& specs, const Params& p, double sse,
                const std::string& name, const Options& o) {
  Params q = p;
  q.erase(name);
  const double sq = RefitAll(s.train, specs, &q, s.train.Sse(s.train.Predict(ToSet(specs, q))), tuning::kPruneRefitRounds, o);
  const double ex = sq - static_cast<double>(s.n_train) * s.var_floor;
  return ex > 0 ? (sq - sse) / ex : 0.0;
}

}  // namespace

void SplitLostMotion(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  const std::vector<std::string> lost = LostMotionEffects(s.order);
  const double excess = s.sse - static_cast<double>(s.n_train) * s.var_floor;
  if (lost.size() != 1 || !s.structured || static_cast<int>(s.order.size()) >= tuning::kMaxEffectsPerChannel ||
      s.sse <= o.none_ratio * static_cast<double>(s.n_train) * s.var_floor || !(excess > 0))
    return;
  const std::string& one = lost.front();
  const double L = LostMotionOf(one, s.sel.at(one));

  const double tau = IntegratedCorrelationTime(s.train, s.pred_train);
  const double n_eff = std::max(1.0, static_cast<double>(s.n_train) / tau);
  const CandidateSpec* one_spec = ChannelSpec(specs, one, s.ch);
  std::optional<Candidate> best;
  for (const char* other : kLostMotion) {
    const CandidateSpec* spec = ChannelSpec(specs, other, s.ch);
    if (spec == nullptr || s.sel.count(other)) continue;
    for (const double phi : tuning::kLostMotionSplits) {
      for (const auto& start : StartsFrom(other, phi * L)) {
        Params t = s.sel;
        t[one][0] = std::clamp(t[one][0] * (1.0 - phi), one_spec->params[0].lo, one_spec->params[0].hi);
        std::vector<double> v = start;
        for (std::size_t j = 0; j < v.size(); ++j) v[j] = std::clamp(v[j], spec->params[j].lo, spec->params[j].hi);
        t[other] = v;
        FitEffect(s.train, specs, &t, other, o);
        const double sse = RefitAll(s.train, specs, &t, s.train.Sse(s.train.Predict(ToSet(specs, t))), o.refit_rounds, o);
        if (AtBound(*spec, t.at(other)) || !FormOf(*spec, t.at(other)).empty() || AtBound(*one_spec, t.at(one)) ||
            !FormOf(*one_spec, t.at(one)).empty())
          continue;
        // Each must lose a fair share of the motion: a small second one is the first's form.
        const double l1 = LostMotionOf(one, t.at(one)), l2 = LostMotionOf(other, t.at(other));
        if (std::min(l1, l2) < tuning::kLostMotionMinShare * (l1 + l2)) continue;
        if (!best || sse < best->sse) best = Candidate{other, t, sse};
      }
    }
  }
  if (!best) return;
  const int p = FreeParams(SpecOf(specs, best->name), s.train.recs().size());
  const double dbic = n_eff * std::log(std::max(best->sse, 1e-300) / std::max(s.sse, 1e-300)) + p * std::log(n_eff);
  const double excess_red = (s.sse - best->sse) / excess;
  if (!(dbic < 0.0) || excess_red < std::max(o.min_excess_reduction, tuning::kLostMotionSplitMinGain) ||
      (s.sse - best->sse) < o.min_floor_gain * static_cast<double>(s.n_train) * s.var_floor)
    return;
  for (const std::string& n : {one, best->name})
    if (OwnShare(s, specs, best->params, best->sse, n, o) < o.min_excess_reduction) return;
  warnings->push_back(fmt::format("channel {}: {} split into {} + {}: the lost motion ({:.3g} mm a side) shared by "
                                  "two effects fits better (training BIC {:.1f} lower, {:.0f} % of the remaining excess)",
                                  s.summary.channel, one, one, best->name, L, -dbic, 100.0 * excess_red));
  AddEffect(&s, specs, best->name, best->params, excess_red, dbic);
}

void WeighLostMotion(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  const std::vector<std::string> lost = LostMotionEffects(s.order);
  if (lost.size() < 2) return;
  double L = 0.0;
  int p_lost = 0;
  Params rest = s.sel;
  for (const auto& n : lost) {
    L += LostMotionOf(n, s.sel.at(n));
    p_lost += FreeParams(SpecOf(specs, n), s.train.recs().size());
    rest.erase(n);
  }
  const double tau = IntegratedCorrelationTime(s.train, s.pred_train);
  const double n_eff = std::max(1.0, static_cast<double>(s.n_train) / tau);
  std::optional<Candidate> best;
  double best_dbic = std::numeric_limits<double>::infinity();
  for (const char* single : kLostMotion) {
    const CandidateSpec* spec = ChannelSpec(specs, single, s.ch);
    if (spec == nullptr) continue;
    Candidate c{single, {}, std::numeric_limits<double>::infinity()};
    // From its whole range, and from the lost motion of the set it would replace (a local refit).
    std::vector<Params> tries;
    Params q = rest;
    FitEffect(s.train, specs, &q, single, o);
    tries.push_back(q);
    for (const auto& start : StartsFrom(single, L)) {
      Params r = rest;
      std::vector<double> v = start;
      for (std::size_t j = 0; j < v.size(); ++j) v[j] = std::clamp(v[j], spec->params[j].lo, spec->params[j].hi);
      r[single] = v;
      FitEffect(s.train, specs, &r, single, o);
      tries.push_back(r);
    }
    for (auto& t : tries) {
      const double sse = RefitAll(s.train, specs, &t, s.train.Sse(s.train.Predict(ToSet(specs, t))), o.refit_rounds, o);
      if (AtBound(*spec, t.at(single)) || !FormOf(*spec, t.at(single)).empty()) continue;
      if (sse < c.sse) c.sse = sse, c.params = t;
    }
    if (!std::isfinite(c.sse)) continue;
    const int p = FreeParams(*spec, s.train.recs().size());
    const double dbic = n_eff * std::log(std::max(c.sse, 1e-300) / std::max(s.sse, 1e-300)) + (p - p_lost) * std::log(n_eff);
    if (dbic < best_dbic) best_dbic = dbic, best = std::move(c);
  }
  if (!best) return;
  const std::string pair = fmt::format("{}", fmt::join(lost, "+"));
  if (best_dbic < 0.0) {
    warnings->push_back(fmt::format("channel {}: {} replaced by {}: one lost-motion effect explains the lost motion the "
                                    "set shared (training BIC {:.1f} lower)",
                                    s.summary.channel, fmt::join(lost, " + "), best->name, -best_dbic));
    // In the place of the first of them, with their evidence.
    const auto first = std::find(s.order.begin(), s.order.end(), lost.front());
    const std::size_t at = static_cast<std::size_t>(first - s.order.begin());
    const auto stats = s.sel_stats[lost.front()];
    for (const auto& n : lost) {
      s.order.erase(std::find(s.order.begin(), s.order.end(), n));
      s.alternatives.erase(n);
      s.sel_stats.erase(n);
    }
    s.sel_stats[best->name] = stats;
    s.order.insert(s.order.begin() + static_cast<std::ptrdiff_t>(std::min(at, s.order.size())), best->name);
    // The set as the single's close call, its parameters keyed "effect.key".
    std::map<std::string, double> merged;
    for (const auto& n : lost)
      for (const auto& [k, v] : ParamMap(specs, n, s.sel.at(n))) merged[n + "." + k] = v;
    s.sel = best->params;
    s.alternatives[best->name].clear();
    if (-best_dbic < tuning::kCloseCallBic) s.alternatives[best->name].push_back({pair, -best_dbic, merged});
    s.pred_train = s.train.Predict(ToSet(specs, s.sel));
    s.sse = s.train.Sse(s.pred_train);
  } else if (best_dbic < tuning::kCloseCallBic) {
    auto& alts = s.alternatives[lost.front()];
    alts.insert(alts.begin(), {best->name, best_dbic, ParamMap(specs, best->name, best->params.at(best->name))});
  }
}

}  // namespace rths::diagnosis::stages
