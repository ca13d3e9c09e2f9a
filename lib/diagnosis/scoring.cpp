#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/candidates.h"
#include "diagnosis/fit.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis::stages {

void ScoreNominal(ChannelState* s, const Options& o) {
  ChannelSummary& cs = s->summary;
  cs.channel = std::string(1, s->ch);
  cs.diagnosed = true;
  s->sel.clear();
  s->order.clear();
  s->pred_train = s->train.Predict({});
  s->nom_test = s->test.Predict({});
  s->sse = s->train.Sse(s->pred_train);
  s->n_train = Count(s->train.recs());
  const double sse_test = s->test.Sse(s->nom_test);
  const double dt = s->train.recs().front().dt;
  for (const auto& [sse, set] : {std::pair{s->sse, &s->train.recs()}, std::pair{sse_test, &s->test.recs()}}) {
    if (std::isfinite(sse)) continue;
    std::string names;
    for (const auto& d : *set) names += (names.empty() ? "" : ", ") + d.source;
    throw Error(names, fmt::format("the nominal model's {} residual is not finite: the model diverged on these "
                                   "records (is dt_s = {} s fine enough for it?) or a value is too large for "
                                   "the arithmetic",
                                   s->ch == 'y' ? "displacement" : "force", dt));
  }
  cs.gap_train_pct = s->train.NrmsePct(s->sse);
  cs.gap_test_pct = s->test.NrmsePct(sse_test);
  const double v_tr = NoiseFloorVar(s->train, s->pred_train, o), v_te = NoiseFloorVar(s->test, s->nom_test, o);
  const double n_tr = static_cast<double>(Count(s->train.recs())), n_te = static_cast<double>(Count(s->test.recs()));
  s->var_floor = (v_tr * n_tr + v_te * n_te) / (n_tr + n_te);
  cs.noise_rms = std::sqrt(s->var_floor);
  const double ms = (s->sse + sse_test) / (n_tr + n_te);
  cs.floor_ratio = s->var_floor > 0 ? ms / s->var_floor : std::numeric_limits<double>::infinity();
  cs.floor_ratio_test = s->var_floor > 0 ? (sse_test / n_te) / s->var_floor : std::numeric_limits<double>::infinity();
  cs.whiteness = Whiteness(s->test, s->nom_test);
  // Structured if the pooled residual is above the floor, or the training records' alone: a long test
  // that does not exercise an effect (a slow test below a flow limit) must not dilute the training
  // records' evidence into "noise".
  const double ratio_train = s->var_floor > 0 ? (s->sse / n_tr) / s->var_floor : std::numeric_limits<double>::infinity();
  s->structured = cs.floor_ratio > o.none_ratio || ratio_train > o.none_ratio;
  s->sse_nominal = s->sse;
  s->excess_nominal = s->sse_nominal - static_cast<double>(s->n_train) * s->var_floor;
}

void MarkNotDiagnosed(ChannelState* s) {
  s->summary.diagnosed = false;
  s->summary.status = "not diagnosed";
  s->structured = false;
  s->fin_test = s->nom_test;
  s->pred_train_fin = s->pred_train;
}

void ScoreSelected(const ChannelState& s, const std::vector<CandidateSpec>& specs, EffectResults* er) {
  const double before = s.summary.gap_test_pct;
  Params cum;
  for (const auto& name : s.order) {
    cum[name] = s.sel.at(name);
    const auto sset = ToSet(specs, cum);
    const auto pt = s.test.Predict(sset, nullptr, true);
    const auto ptr = s.train.Predict(sset, nullptr, true);
    const auto stats = s.sel_stats.find(name);
    EffectResult e;
    e.name = name;
    e.channel = s.summary.channel;
    e.params = ParamMap(specs, name, s.sel.at(name));
    e.test_nrmse_after = s.test.NrmsePct(s.test.Sse(pt));
    e.train_nrmse_after = s.train.NrmsePct(s.train.Sse(ptr));
    e.shrink_pct = ShrinkPct(before, e.test_nrmse_after);
    e.selected = true;
    e.excess_reduction = stats == s.sel_stats.end() ? 0.0 : stats->second.first;
    e.delta_bic = stats == s.sel_stats.end() ? 0.0 : stats->second.second;
    if (const auto a = s.alternatives.find(name); a != s.alternatives.end()) e.alternatives = a->second;
    (*er)[name] = e;
  }
}

/// How much the selected effects change the predictions, training and test, in units of the
/// noise floor's power: sum_k (pred - nominal)^2 / (n sigma^2) over the samples of the sums.
std::pair<double, double> Footprints(const ChannelState& s, const std::vector<std::vector<double>>& fin_test) {
  const double s2 = s.summary.noise_rms * s.summary.noise_rms;
  auto footprint = [s2](const Channel& c, const std::vector<std::vector<double>>& a,
                        const std::vector<std::vector<double>>& b) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t r = 0; r < c.recs().size(); ++r)
      for (std::size_t k = c.recs()[r].first; k < a[r].size(); ++k, ++n) sum += (a[r][k] - b[r][k]) * (a[r][k] - b[r][k]);
    return n > 0 && s2 > 0.0 ? sum / (static_cast<double>(n) * s2) : 0.0;
  };
  return {footprint(s.train, s.pred_train, s.train.Predict({})), footprint(s.test, fin_test, s.nom_test)};
}

/// The evidence of an unconfirmed effect `name` (EffectResult::unconfirmed).
std::string UnconfirmedText(const ChannelState& s, const std::string& name, double fp_train, double fp_test) {
  const auto st = s.sel_stats.find(name);
  return fmt::format(
      "on the training records it removes {:.0f} % of the residual above noise and changes the prediction by "
      "{:.3g} x the noise floor's power; on the test records by only {:.2g} x: the test does not exercise it",
      100.0 * (st == s.sel_stats.end() ? 0.0 : st->second.first), fp_train, fp_test);
}

/// If the selected effects change the test prediction by less than kUnconfirmedTestFootprint x the
/// noise floor's power while changing the training prediction by at least kUnconfirmedTrainFootprint x,
/// names them unconfirmed (their evidence in er, s.unconfirmed, a warning saying `why_test`) and
/// returns true.
bool NameUnconfirmed(ChannelState* sp, const std::vector<std::vector<double>>& fin, const char* why_test,
                     std::vector<std::string>* warnings, EffectResults* er) {
  ChannelState& s = *sp;
  const auto [fp_train, fp_test] = Footprints(s, fin);
  if (!(fp_test < tuning::kUnconfirmedTestFootprint && fp_train >= tuning::kUnconfirmedTrainFootprint)) return false;
  for (const auto& n : s.order) (*er)[n].unconfirmed = UnconfirmedText(s, n, fp_train, fp_test);
  s.unconfirmed = s.order;
  warnings->push_back(fmt::format("channel {}: {} found on the training records, unconfirmed: the test records {}do "
                                  "not exercise {} (their prediction changes by {:.2g} x the noise floor's power)",
                                  s.summary.channel, fmt::join(s.order, ", "), why_test,
                                  s.order.size() > 1 ? "them" : "it", fp_test));
  return true;
}

void ApplyShrinkRule(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings, EffectResults* er) {
  ChannelState& s = *sp;
  ChannelSummary& cs = s.summary;
  const double before = cs.gap_test_pct;
  auto fin = s.test.Predict(ToSet(specs, s.sel), nullptr, true);
  cs.after_test_pct = s.test.NrmsePct(s.test.Sse(fin));
  const bool test_structured = cs.floor_ratio_test > o.none_ratio;
  bool retained = !s.order.empty();
  if (retained && test_structured && ShrinkPct(before, cs.after_test_pct) < o.min_test_shrink_pct) {
    // The test records may not exercise the effects: then neither confirmed nor refuted.
    if (!NameUnconfirmed(&s, fin, "", warnings, er)) {
      warnings->push_back(fmt::format(
          "channel {}: the effects selected on the training records ({}) shrink the test gap by only {:.1f} % "
          "(< {:.0f} %): not retained",
          cs.channel, fmt::join(s.order, ", "), ShrinkPct(before, cs.after_test_pct), o.min_test_shrink_pct));
    }
    for (const auto& n : s.order) (*er)[n].selected = false;
    cs.after_test_pct = before;
    retained = false;
  } else if (retained && !test_structured) {
    // Kept (they do no harm on the test); named unconfirmed if the test cannot show them.
    if (!NameUnconfirmed(&s, fin, "are at the noise floor and ", warnings, er)) {
      warnings->push_back(fmt::format("channel {}: the test records' residual is at the noise floor; the effects "
                                      "were found on the training records only",
                                      cs.channel));
    }
  }
  s.fin_set = retained ? ToSet(specs, s.sel) : models::EffectSet{};
  if (retained) {
    s.fin_test = std::move(fin);
    s.pred_train_fin = s.pred_train;
  } else {
    s.fin_test = s.nom_test;
    s.pred_train_fin = s.train.Predict({});
  }
  if (!s.structured) cs.status = "noise";
  else if (!s.unconfirmed.empty()) cs.status = "unconfirmed";
  else if (retained) cs.status = "explained";
  else cs.status = "unexplained";
  s.retained = retained;
}

void ScoreCandidates(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o, EffectResults* er) {
  ChannelState& s = *sp;
  const double before = s.summary.gap_test_pct;
  if (!s.retained && !s.order.empty() && s.unconfirmed.empty()) {
    for (auto& [name, t] : s.last_trial) {
      Params q;
      t.sse = FitEffect(s.train, specs, &q, name, o);
      t.params = q;
      t.excess_red = s.excess_nominal > 0 ? (s.sse_nominal - t.sse) / s.excess_nominal : 0.0;
      t.dbic = std::nan("");
    }
    for (const auto& name : s.order) {
      Trial t;
      t.name = name;
      t.sse = FitEffect(s.train, specs, &t.params, name, o);
      t.excess_red = s.excess_nominal > 0 ? (s.sse_nominal - t.sse) / s.excess_nominal : 0.0;
      t.dbic = std::nan("");
      s.last_trial[name] = t;
      er->erase(name);
    }
  }
  for (const auto& [name, t] : s.last_trial) {
    if (er->count(name)) continue;
    const auto pt = s.test.Predict(ToSet(specs, t.params), nullptr, true);
    EffectResult e;
    e.name = name;
    e.channel = s.summary.channel;
    e.params = ParamMap(specs, name, t.params.at(name));
    e.test_nrmse_after = s.test.NrmsePct(s.test.Sse(pt));
    e.train_nrmse_after = s.train.NrmsePct(t.sse);
    e.shrink_pct = ShrinkPct(before, e.test_nrmse_after);
    e.excess_reduction = t.excess_red;
    e.delta_bic = t.dbic;
    const CandidateSpec& spec = SpecOf(specs, name);
    e.at_bound = AtBound(spec, t.params.at(name));
    e.form_of = FormOf(spec, t.params.at(name));
    (*er)[name] = e;
  }
}

}  // namespace rths::diagnosis::stages
