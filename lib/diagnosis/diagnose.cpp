#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/diagnosis.h"
#include "diagnosis/localise.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"
#include "diagnosis/verdict.h"

namespace rths::diagnosis {

namespace {

using stages::Channel;
using stages::ChannelState;
using stages::Data;
using stages::EffectResults;
using stages::SumSq;

/// The records' common dt [s]. Throws rths::Error if a set is empty or a record's dt differs.
double CommonDt(const std::vector<io::RigRecord>& train_in, const std::vector<io::RigRecord>& test_in) {
  if (train_in.empty()) throw Error("--train", "at least one training record is needed");
  if (test_in.empty()) throw Error("--test", "at least one test record is needed");
  const double dt = train_in[0].dt_s;
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      if (std::abs(r.dt_s - dt) > 1e-9 * dt)
        throw Error(r.source, fmt::format("dt_s {} differs from the first training record's {} (one dt per diagnosis)",
                                          r.dt_s, dt));
  return dt;
}

/// true if the force channel can be diagnosed: the model has a damper and the training records'
/// force is not all zero; else false and a warning says why.
bool ForceChannelUsable(const NominalModel& model, const std::vector<Data>& train, std::vector<std::string>* warnings) {
  bool force_ok = model.has_damper;
  if (force_ok) {
    double s = 0;
    for (const auto& d : train) s += SumSq(d.f, d.first);
    if (!(s > 0)) {
      force_ok = false;
      warnings->push_back("the training records' force is zero: the force channel is not diagnosed");
    }
  } else {
    warnings->push_back("the model has no damper part: the force channel is not diagnosed");
  }
  return force_ok;
}

/// Upper end of vmax's search range [mm/s]: tuning::kVmaxSearchFactor x the largest measured velocity
/// of the training records, at most the effect library's limit for vmax (1e9 mm/s; a jump in a
/// record can exceed it).
double VmaxSearchHi(const std::vector<Data>& train, double dt) {
  double vmax_meas = 1.0;
  for (const auto& d : train)
    for (std::size_t k = 1; k < d.size(); ++k) vmax_meas = std::max(vmax_meas, std::abs(d.y[k] - d.y[k - 1]) / dt);
  return std::min(tuning::kVmaxSearchFactor * vmax_meas, 1e9);
}

/// false if u = y in every record (a displacement-only test, e.g. the UTFSM damper tests: predicting
/// y from u would only show the model's own lag), with a warning; else true.
bool DisplacementChannelUsable(const std::vector<Data>& train, const std::vector<Data>& test,
                               std::vector<std::string>* warnings) {
  bool y_ok = false;
  for (const auto* set : {&train, &test})
    for (const auto& d : *set) y_ok |= d.u != d.y;
  if (!y_ok)
    warnings->push_back("u = y in every record (a displacement-only test): the displacement channel is not diagnosed");
  return y_ok;
}

/// The cutoff of the y residual's smoothing for the damper's motion [Hz].
double MotionCutoffHz(const Options& o, double dt) { return std::min(o.smooth_hz, o.max_smooth_cycles_per_sample / dt); }

/// The motion of the damper in every record: y's final model plus the zero-phase-smoothed
/// residual (ModelAidedMotion); without a displacement model to lean on (u = y), the measured y
/// smoothed at a cutoff above the excitation.
void SetForceMotion(std::vector<Data>* train, std::vector<Data>* test, const ChannelState& y, bool y_ok,
                    const models::LinearServo& servo, const Options& o, double dt) {
  // The damper's acceleration (load_cell_inertia): the motion's own, else its velocity's derivative.
  auto set_acc = [dt](Data& d) {
    if (d.motion.a_mm_s2.size() == d.size()) d.acc_mm_s2 = d.motion.a_mm_s2;
    else Differentiate(d.motion.v_mm_s, dt, &d.acc_mm_s2);
  };
  if (!y_ok) {
    const double fc = std::min(tuning::kDisplacementOnlySmoothFactor * o.smooth_hz, o.max_smooth_cycles_per_sample / dt);
    for (auto* recs : {train, test})
      for (auto& d : *recs) d.motion = SmoothMotion(d.y, dt, fc), set_acc(d);
    return;
  }
  // The final model's own velocity and acceleration (exact for the servo) under the smoothed
  // residual's.
  auto motion = [&](const Data& d) {
    std::vector<double> vhat, ahat;
    const std::vector<double> yhat = PredictDisplacement(servo, y.fin_set, d.u, d.f, &vhat, &ahat, d.y, d.first);
    return ModelAidedMotion(d.y, yhat, vhat, dt, MotionCutoffHz(o, dt), ahat);
  };
  for (auto* recs : {train, test})
    for (auto& d : *recs) d.motion = motion(d), set_acc(d);
}

/// The damper's motion in every test record for the localisation's conditions: the force
/// channel's own (SetForceMotion), else y's final model plus its smoothed residual.
std::vector<SmoothedMotion> TestMotions(const ChannelState& y, const std::vector<Data>& test, const Options& o, double dt) {
  std::vector<SmoothedMotion> motions;
  motions.reserve(test.size());
  for (std::size_t r = 0; r < test.size(); ++r) {
    const auto& d = test[r];
    motions.push_back(d.motion.v_mm_s.empty() ? ModelAidedMotion(d.y, y.fin_test[r], {}, dt, MotionCutoffHz(o, dt))
                                              : d.motion);
  }
  return motions;
}

/// Where (test records, nominal model): bands, conditions and time windows of the channel's residual.
void LocaliseChannel(const ChannelState& s, const std::vector<Data>& test, const std::vector<SmoothedMotion>& motions,
                     const Options& o, Result* res) {
  std::vector<LocaliseInput> li;
  for (std::size_t r = 0; r < test.size(); ++r) {
    const auto& d = test[r];
    LocaliseInput in;
    in.source = d.source;
    in.dt_s = d.dt;
    in.first = d.first;
    in.u = d.u;
    in.meas = s.ch == 'y' ? std::span<const double>(d.y) : std::span<const double>(d.f);
    in.pred = s.nom_test[r];
    in.v = motions[r].v_mm_s;
    in.f_meas = d.f;
    in.i = d.i;
    li.push_back(in);
  }
  const std::size_t first_condition = res->conditions.size();
  Localise(std::string(1, s.ch), li, &res->bands, &res->conditions, &res->time);
  for (std::size_t j = first_condition; j < res->conditions.size(); ++j) {
    Condition& cond = res->conditions[j];
    cond.informative = cond.samples_pct > 0.0 && cond.samples_pct <= o.max_condition_samples_pct;
  }
}

/// The test records' traces for the report's plots (nominal and final models of both channels).
void MakeTraces(const std::vector<ChannelState>& st, const std::vector<Data>& test,
                const std::vector<SmoothedMotion>& motions, Traces* traces) {
  traces->test.clear();
  for (std::size_t r = 0; r < test.size(); ++r) {
    const auto& d = test[r];
    Traces::Record tr;
    tr.source = d.source;
    tr.dt_s = d.dt;
    tr.u = d.u;
    tr.y_meas = d.y;
    tr.i = d.i;
    tr.v = motions[r].v_mm_s;
    tr.y_nom = st[0].nom_test[r];
    tr.y_fin = st[0].fin_test[r];
    tr.f_meas = d.f;
    if (st.size() > 1) {
      tr.f_nom = st[1].nom_test[r];
      tr.f_fin = st[1].fin_test[r];
    }
    traces->test.push_back(std::move(tr));
  }
}

/// The result before the stages: the options, dt, the model, the records' names and sample count,
/// and the warnings of the model and the records, with every stuck or clipped sensor stretch.
Result StartResult(const std::vector<io::RigRecord>& train_in, const std::vector<io::RigRecord>& test_in,
                   const std::vector<Data>& train, const std::vector<Data>& test, const NominalModel& model,
                   const Options& o, double dt) {
  Result res;
  res.options = o;
  res.dt_s = dt;
  res.model_source = model.source;
  for (const auto& n : model.notes) res.warnings.push_back(n);
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      for (const auto& w : r.warnings) res.warnings.push_back(w);
  for (const auto& d : train) res.train.push_back(d.source);
  for (const auto& d : test) res.test.push_back(d.source);
  res.samples = stages::Count(train) + stages::Count(test);
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      for (const SensorFault& sf : FindFlatSensors(r, o.sensor_flat_s)) {
        res.warnings.push_back(fmt::format("{}: {} holds exactly {} from {:.3f} s to {:.3f} s while the rig moves: a "
                                           "stuck or clipped sensor? (its residual there is not a model error)",
                                           sf.record, sf.channel, sf.value, sf.t0_s, sf.t1_s));
        res.sensor_faults.push_back(sf);
      }
  return res;
}

/// The stages of one diagnosed channel (stages.h), in order; progress over [base, base + 10) of
/// total. Appends the channel's retained effects to *verdict.
void RunStages(ChannelState* s, const std::vector<stages::CandidateSpec>& specs, const Options& o, double base,
               double total, Result* res, EffectResults* er, std::vector<std::string>* verdict) {
  // Progress: selection is most of a channel's time; the other stages share the rest.
  const std::string ch(1, s->ch);
  if (o.progress) o.progress(base, total, "channel " + ch + ": fitting and selecting effects");
  stages::SelectEffects(s, specs, o);
  if (o.progress) o.progress(base + 6, total, "channel " + ch + ": swaps and pruning");
  stages::SwapEffects(s, specs, o, &res->warnings);
  stages::PruneEffects(s, specs, o, &res->warnings);
  stages::SplitLostMotion(s, specs, o, &res->warnings);
  stages::WeighLostMotion(s, specs, o, &res->warnings);
  if (o.progress) o.progress(base + 8, total, "channel " + ch + ": held-out test");
  stages::RetainOnTest(s, specs, o, &res->warnings);
  stages::ScoreSelected(*s, specs, er);
  stages::ApplyShrinkRule(s, specs, o, &res->warnings, er);
  stages::AssessParameters(*s, specs, er, &res->warnings);
  if (o.progress) o.progress(base + 9, total, "channel " + ch + ": scoring the other candidates");
  // The retained effects (unconfirmed or not), else the unconfirmed ones (not retained).
  for (const auto& n : s->retained ? s->order : s->unconfirmed) verdict->push_back(n);
  stages::ScoreCandidates(s, specs, o, er);
}

/// --detrend for one channel (stages::RemoveSensorDrift): the drift of the nominal residual out, a
/// scratch selection of effects on that, then, from the original measurement, the drift of the
/// residual under the selected effects out (notes into *warnings).
void RemoveDrift(char chan, std::vector<Data>* train, std::vector<Data>* test, const models::LinearServo& servo,
                 const ForcePredictor* fp, const std::vector<stages::CandidateSpec>& specs, const Options& o,
                 std::vector<std::string>* warnings) {
  auto meas = [chan](Data& d) -> std::vector<double>& { return chan == 'y' ? d.y : d.f; };
  std::vector<std::vector<double>> original;
  for (auto* recs : {train, test})
    for (auto& d : *recs) original.push_back(meas(d));
  for (auto* recs : {train, test}) stages::RemoveSensorDrift(chan, recs, servo, fp, {}, nullptr);
  ChannelState scratch(chan, Channel(chan, train, &servo, fp), Channel(chan, test, &servo, fp));
  Options quiet = o;
  quiet.progress = nullptr;
  stages::ScoreNominal(&scratch, quiet);
  Result res;
  EffectResults er;
  std::vector<std::string> verdict;
  RunStages(&scratch, specs, quiet, 0.0, 10.0, &res, &er, &verdict);
  std::size_t j = 0;
  for (auto* recs : {train, test})
    for (auto& d : *recs) meas(d) = original[j++];
  for (auto* recs : {train, test}) stages::RemoveSensorDrift(chan, recs, servo, fp, scratch.fin_set, warnings);
}

/// A channel whose training records sit at their noise floor while its test records do not: the
/// training records do not exercise what the test shows (a flow limit the training commands never
/// reach). Its effects are then selected with the roles swapped (the test records fitted, the
/// training records as the check) and named as found on the test records only (their
/// EffectResult::unconfirmed says so; not in the final model): nothing holds them out, so they
/// must explain at least tuning::kTestOnlyMinExplained of the test's excess over the floor, else
/// the channel stays unexplained (an effect outside the library).
void TestOnlyEffects(ChannelState* s, std::vector<Data>* train, std::vector<Data>* test, const models::LinearServo& servo,
                     const ForcePredictor* fp, const std::vector<stages::CandidateSpec>& specs, const Options& o,
                     Result* res, EffectResults* er, std::vector<std::string>* verdict) {
  const double floor = s->var_floor;
  const double ratio_train = floor > 0 && s->n_train > 0 ? s->sse_nominal / static_cast<double>(s->n_train) / floor : 0.0;
  if (!s->order.empty() || !s->unconfirmed.empty() || !s->summary.diagnosed || !(floor > 0) ||
      ratio_train > o.none_ratio || !(s->summary.floor_ratio_test > o.none_ratio))
    return;
  Options quiet = o;
  quiet.progress = nullptr;
  ChannelState sw(s->ch, Channel(s->ch, test, &servo, fp), Channel(s->ch, train, &servo, fp));
  sw.min_skew_s = s->min_skew_s;
  stages::ScoreNominal(&sw, quiet);
  std::vector<std::string> scratch;
  stages::SelectEffects(&sw, specs, quiet);
  stages::SwapEffects(&sw, specs, quiet, &scratch);
  stages::PruneEffects(&sw, specs, quiet, &scratch);
  if (sw.order.empty() || !(sw.excess_nominal > 0)) return;
  const double explained = (sw.sse_nominal - sw.sse) / sw.excess_nominal;
  if (explained < tuning::kTestOnlyMinExplained) return;
  EffectResults found;
  stages::ScoreSelected(sw, specs, &found);
  const std::string why = fmt::format(
      "found on the test records only: the training records sit at the noise floor ({:.2f} x) and do not exercise it, "
      "so nothing holds it out (fitted on the test, it explains {:.0f} % of their excess)",
      ratio_train, 100.0 * explained);
  for (const auto& name : sw.order) {
    EffectResult e = found.at(name);
    std::swap(e.train_nrmse_after, e.test_nrmse_after);  // sw's training records are the test
    e.shrink_pct = ShrinkPct(s->summary.gap_test_pct, e.test_nrmse_after);
    e.unconfirmed = why;
    e.selected = false;  // not in the final model, as an unconfirmed effect
    (*er)[name] = e;
    s->unconfirmed.push_back(name);
    verdict->push_back(name);
  }
  s->summary.status = "test only";
  res->warnings.push_back(fmt::format("channel {}: {} {}", s->summary.channel, fmt::join(sw.order, " + "), why));
}

}  // namespace

Result Diagnose(const std::vector<io::RigRecord>& train_in, const std::vector<io::RigRecord>& test_in,
                const NominalModel& model, const Options& o, Traces* traces) {
  const auto t_start = std::chrono::steady_clock::now();
  std::string why;
  if (!o.IsValid(&why)) throw Error("diagnosis options", why);
  const double dt = CommonDt(train_in, test_in);
  std::vector<Data> train, test;
  for (const auto& r : train_in) train.push_back(stages::Prepare(r, o));
  for (const auto& r : test_in) test.push_back(stages::Prepare(r, o));
  std::vector<std::string> start_notes;
  for (auto* recs : {&train, &test})
    for (auto& d : *recs) stages::ExtendWarmupIfMoving(&d, model, &start_notes);
  Result res = StartResult(train_in, test_in, train, test, model, o, dt);
  res.warnings.insert(res.warnings.end(), start_notes.begin(), start_notes.end());

  const auto servo = models::LinearServo::Make(model.actuator, dt);
  std::optional<ForcePredictor> fp;
  if (model.has_damper) fp.emplace(model.damper, model.current_dynamics, dt, model.current_driver);
  const ForcePredictor* fpp = fp ? &*fp : nullptr;
  // A force channel that is all zeros cannot be diagnosed either.
  const bool force_ok = ForceChannelUsable(model, train, &res.warnings);
  const auto specs = stages::Candidates(dt, VmaxSearchHi(train, dt));
  const bool y_ok = DisplacementChannelUsable(train, test, &res.warnings);

  // The channels are diagnosed one after the other: y first, then f, whose motion input is the
  // measured y seen through y's final model (ModelAidedMotion).
  std::vector<char> chans = {'y'};
  if (force_ok) chans.push_back('f');
  std::vector<ChannelState> st;
  st.reserve(chans.size());  // st[0] is referenced while f's state is added
  EffectResults er;
  std::vector<std::string> verdict;
  for (char chan : chans) {
    if (chan == 'f') {
      SetForceMotion(&train, &test, st[0], y_ok, servo, o, dt);
      for (auto* recs : {&train, &test})
        for (auto& d : *recs) stages::EstimateCurrentStart(&d, *fp, model, &res.warnings);
    }
    // --detrend: the sensor's drift out of this channel's measurement only (u = y: y has none to
    // lean on, its drift is in the command too). Without it, a channel whose whole excess lies
    // below the drift band is a drifting sensor too: removed the same way, and scored again (a
    // Channel holds its measurement's sum of squares, so it is made anew).
    const bool drift_ok = chan == 'f' || y_ok;
    if (o.detrend && drift_ok) RemoveDrift(chan, &train, &test, servo, fpp, specs, o, &res.warnings);
    st.emplace_back(chan, Channel(chan, &train, &servo, fpp), Channel(chan, &test, &servo, fpp));
    auto& s = st.back();
    if (chan == 'f' && !st[0].fin_set.Empty()) s.min_skew_s = dt;  // rule 8
    stages::ScoreNominal(&s, o);
    if (!o.detrend && drift_ok && stages::ExcessIsSlow(s, o.none_ratio)) {
      res.warnings.push_back(fmt::format("channel {}: its whole excess over the noise floor lies below {:g} Hz: a "
                                         "drifting sensor, removed as --detrend removes it (sensor_drift below)",
                                         chan, tuning::kDriftHz));
      RemoveDrift(chan, &train, &test, servo, fpp, specs, o, &res.warnings);
      const double min_skew_s = s.min_skew_s;
      s = ChannelState(chan, Channel(chan, &train, &servo, fpp), Channel(chan, &test, &servo, fpp));
      s.min_skew_s = min_skew_s;
      stages::ScoreNominal(&s, o);
    }
    if (s.ch == 'y' && !y_ok) {
      stages::MarkNotDiagnosed(&s);
    } else {
      const double base = 10.0 * static_cast<double>(st.size() - 1);  // this channel's index
      RunStages(&s, specs, o, base, 10.0 * static_cast<double>(chans.size()), &res, &er, &verdict);
      TestOnlyEffects(&s, &train, &test, servo, fpp, specs, o, &res, &er, &verdict);
    }
    res.channels.push_back(s.summary);
  }
  if (!force_ok) {
    ChannelSummary cs;
    cs.channel = "f";
    cs.diagnosed = false;
    cs.status = "not diagnosed";
    res.channels.push_back(cs);
  }
  RankEffects(verdict, &er, st.size(), &res);
  FormVerdict(verdict, st, &res);
  const auto motions = TestMotions(st[0], test, o, dt);
  for (std::size_t c = 0; c < st.size(); ++c)
    if (res.channels[c].diagnosed) LocaliseChannel(st[c], test, motions, o, &res);
  if (traces) MakeTraces(st, test, motions, traces);
  res.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

}  // namespace rths::diagnosis
