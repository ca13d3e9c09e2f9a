// The stages of the diagnosis one at a time (lib/diagnosis/stages.h), on short synthetic records
// from the effect blocks: the nominal scoring, the greedy selection, the pruning, the held-out
// retention and the shrink rule, each run on a channel state set up by hand.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "diagnosis/candidates.h"
#include "diagnosis/diagnosis.h"
#include "diagnosis/fit.h"
#include "diagnosis/ripple_fit.h"
#include "diagnosis/stages.h"
#include "synthetic_records.h"
#include "validation/synthetic.h"
#include "models/servo_linear.h"
#include "signal/random.h"

using namespace rths::diagnosis;
using namespace rths::validation;
namespace m = rths::models;
namespace st = rths::diagnosis::stages;

namespace {

/// Short training (BLWN 0-25 Hz) and test (BLWN 0-8 Hz) records with sensor noise.
std::pair<rths::io::RigRecord, rths::io::RigRecord> Records(const m::EffectSet& effects) {
  Truth truth;
  truth.effects = effects;
  truth.effects.sensor_noise = m::SensorNoise{0.01, 0.2};
  return rths_test::Records(truth);
}

/// The displacement channel of one training and one test record, as Diagnose sets it up.
struct YChannel {
  YChannel(const m::EffectSet& effects, const Options& o = {}) {
    const auto [tr, te] = Records(effects);
    train.push_back(st::Prepare(tr, o));
    test.push_back(st::Prepare(te, o));
    servo = m::LinearServo::Make(PaperModel().actuator, tr.dt_s);
    specs = st::Candidates(tr.dt_s, 1e4);
    state.emplace_back('y', st::Channel('y', &train, &servo, nullptr), st::Channel('y', &test, &servo, nullptr));
  }
  st::ChannelState& s() { return state.front(); }
  /// Holds the given effects as the selection (in this order), with the training SSE they give.
  void Select(const st::Params& sel, const std::vector<std::string>& order) {
    s().sel = sel;
    s().order = order;
    s().pred_train = s().train.Predict(st::ToSet(specs, sel));
    s().sse = s().train.Sse(s().pred_train);
  }
  std::vector<st::Data> train, test;
  m::LinearServo servo;
  std::vector<st::CandidateSpec> specs;
  std::vector<st::ChannelState> state;  // one element (a ChannelState needs its channels to be made)
};

bool Mentions(const std::vector<std::string>& warnings, const std::string& a, const std::string& b) {
  return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) {
    return w.find(a) != std::string::npos && w.find(b) != std::string::npos;
  });
}

}  // namespace

TEST_CASE("ScoreNominal: a noise-only residual is at its floor, a delayed one is structured") {
  const Options o;
  YChannel noise(m::EffectSet{});
  st::ScoreNominal(&noise.s(), o);
  CHECK(noise.s().summary.diagnosed);
  CHECK(noise.s().summary.noise_rms == doctest::Approx(0.01).epsilon(0.15));
  CHECK(noise.s().summary.floor_ratio <= o.none_ratio);
  CHECK_FALSE(noise.s().structured);
  CHECK(noise.s().sse == noise.s().sse_nominal);

  m::EffectSet delay;
  delay.pure_delay = m::PureDelay{4.0};
  YChannel delayed(delay);
  st::ScoreNominal(&delayed.s(), o);
  CHECK(delayed.s().structured);
  CHECK(delayed.s().summary.floor_ratio > 10.0 * o.none_ratio);
  CHECK(delayed.s().excess_nominal > 0.0);
}

TEST_CASE("SelectEffects: picks the known effect and its parameter, and nothing on noise") {
  const Options o;
  m::EffectSet delay;
  delay.pure_delay = m::PureDelay{4.0};
  YChannel y(delay);
  st::ScoreNominal(&y.s(), o);
  const double sse_nominal = y.s().sse;
  st::SelectEffects(&y.s(), y.specs, o);
  REQUIRE(y.s().order == std::vector<std::string>{"pure_delay"});
  CHECK(y.s().sel.at("pure_delay")[0] == doctest::Approx(4.0).epsilon(0.05));
  CHECK(y.s().sse < 0.1 * sse_nominal);
  CHECK(y.s().last_trial.count("pure_delay") == 0);  // selected: no longer a trial
  CHECK(y.s().last_trial.count("gain_error") == 1);  // tried on top of the delay, not passed
  CHECK_FALSE(y.s().last_trial.at("gain_error").pass);

  YChannel noise(m::EffectSet{});
  st::ScoreNominal(&noise.s(), o);
  st::SelectEffects(&noise.s(), noise.specs, o);
  CHECK(noise.s().order.empty());
  CHECK(noise.s().last_trial.size() == 10);  // every displacement candidate tried
}

TEST_CASE("lost motion: presliding is told from backlash by its creep after a reversal") {
  const Options o;
  m::EffectSet dahl;
  dahl.presliding_friction = m::PreslidingFriction{0.2, 0.3};  // creeps at 0.3 / 0.7 = 43 % of the input's rate
  YChannel p(dahl);
  st::ScoreNominal(&p.s(), o);
  st::SelectEffects(&p.s(), p.specs, o);
  REQUIRE(p.s().order == std::vector<std::string>{"presliding_friction"});
  CHECK(p.s().sel.at("presliding_friction")[0] == doctest::Approx(0.2).epsilon(0.1));
  CHECK(p.s().sel.at("presliding_friction")[1] == doctest::Approx(0.3).epsilon(0.2));

  m::EffectSet play;
  play.backlash = m::Backlash{0.4};
  YChannel b(play);
  st::ScoreNominal(&b.s(), o);
  st::SelectEffects(&b.s(), b.specs, o);
  REQUIRE(b.s().order == std::vector<std::string>{"backlash"});
  // Rule 7: a presliding fit that stands still after a reversal is backlash's form.
  const auto& spec = st::SpecOf(b.specs, "presliding_friction");
  CHECK(st::FormOf(spec, {0.2, 0.01}) == "backlash");  // creeps at 0.01 / 0.41 = 2.4 %
  CHECK(st::FormOf(spec, {0.2, 0.1}).empty());         // 20 %
  CHECK(st::FormOf(st::SpecOf(b.specs, "backlash"), {0.4}).empty());
}

TEST_CASE("CloseCalls: the passing trials of a step within kCloseCallBic of the winner, closest first") {
  const auto specs = st::Candidates(0.0005, 1e4);
  auto trial = [&](const std::string& name, double sse, bool pass) {
    st::Trial t;
    t.name = name;
    t.sse = sse;
    t.pass = pass;
    const auto& spec = st::SpecOf(specs, name);
    std::vector<double> v;
    for (const auto& q : spec.params) v.push_back(q.lo * 2.0);
    t.params[name] = v;
    return t;
  };
  const st::Trial best = trial("backlash", 100.0, true);
  std::map<std::string, st::Trial> trials = {
      {"backlash", best},
      {"presliding_friction", trial("presliding_friction", 100.1, true)},  // 1000 ln 1.001 + ln 1000 = 7.9
      {"coulomb_friction", trial("coulomb_friction", 100.5, true)},        // 1000 ln 1.005 = 5.0
      {"command_dead_band", trial("command_dead_band", 101.5, true)},      // 14.9: decided
      {"gain_error", trial("gain_error", 100.0, false)},                   // failed a rule
  };
  const double n_eff = 1000.0;
  const auto alts = st::CloseCalls(trials, best, n_eff, specs, 1);
  REQUIRE(alts.size() == 2);
  CHECK(alts[0].name == "coulomb_friction");
  CHECK(alts[0].delta_bic == doctest::Approx(1000.0 * std::log(1.005)));
  CHECK(alts[1].name == "presliding_friction");
  CHECK(alts[1].delta_bic == doctest::Approx(1000.0 * std::log(1.001) + std::log(1000.0)));
  CHECK(alts[1].params.count("travel_mm") == 1);
}

TEST_CASE("PruneEffects: an effect that explains nothing is removed, two needed ones are kept") {
  const Options o;
  {
    m::EffectSet delay;
    delay.pure_delay = m::PureDelay{4.0};
    YChannel y(delay);
    st::ScoreNominal(&y.s(), o);
    y.Select({{"pure_delay", {4.0}}, {"gain_error", {1.0}}}, {"pure_delay", "gain_error"});  // gain 1: no effect
    std::vector<std::string> warnings;
    st::PruneEffects(&y.s(), y.specs, o, &warnings);
    CHECK(y.s().order == std::vector<std::string>{"pure_delay"});
    CHECK(y.s().sel.count("gain_error") == 0);
    CHECK(Mentions(warnings, "gain_error", "pruned"));
    CHECK(y.s().sse == y.s().train.Sse(y.s().train.Predict(st::ToSet(y.specs, y.s().sel))));
  }
  {
    m::EffectSet both;
    both.pure_delay = m::PureDelay{4.0};
    both.gain_error = m::GainError{1.1};
    YChannel y(both);
    st::ScoreNominal(&y.s(), o);
    y.Select({{"pure_delay", {4.0}}, {"gain_error", {1.1}}}, {"pure_delay", "gain_error"});
    std::vector<std::string> warnings;
    st::PruneEffects(&y.s(), y.specs, o, &warnings);
    CHECK(y.s().order == std::vector<std::string>{"pure_delay", "gain_error"});
    CHECK(warnings.empty());
  }
}

TEST_CASE("PruneEffects: a pure_delay shorter than a sample beside another effect is removed; one longer is kept") {
  const Options o;
  m::EffectSet oil;
  oil.oil_column_resonance = m::OilColumnResonance{25.0, 0.1};
  YChannel y(oil);
  st::ScoreNominal(&y.s(), o);
  const double dt_ms = 1e3 * y.train.front().dt;
  // Half a sample of delay beside the right mode: a timing convention, not a transport delay.
  y.Select({{"oil_column_resonance", {25.0, 0.1}}, {"pure_delay", {0.5 * dt_ms}}}, {"oil_column_resonance", "pure_delay"});
  std::vector<std::string> warnings;
  st::PruneEffects(&y.s(), y.specs, o, &warnings);
  CHECK(y.s().order == std::vector<std::string>{"oil_column_resonance"});
  CHECK(y.s().sel.count("pure_delay") == 0);
  CHECK(Mentions(warnings, "pure_delay", "shorter than"));
  // The same with the rule off (min_delay_samples = 0) keeps it unless its share is too small.
  Options off = o;
  off.min_delay_samples = 0.0;
  y.Select({{"oil_column_resonance", {25.0, 0.1}}, {"pure_delay", {0.5 * dt_ms}}}, {"oil_column_resonance", "pure_delay"});
  warnings.clear();
  st::PruneEffects(&y.s(), y.specs, off, &warnings);
  CHECK_FALSE(Mentions(warnings, "pure_delay", "shorter than"));

  // A real delay of several samples beside a gain error stays.
  m::EffectSet both;
  both.pure_delay = m::PureDelay{4.0};
  both.gain_error = m::GainError{1.1};
  YChannel z(both);
  st::ScoreNominal(&z.s(), o);
  z.Select({{"pure_delay", {4.0}}, {"gain_error", {1.1}}}, {"pure_delay", "gain_error"});
  warnings.clear();
  st::PruneEffects(&z.s(), z.specs, o, &warnings);
  CHECK(z.s().order == std::vector<std::string>{"pure_delay", "gain_error"});
  CHECK(warnings.empty());
}

TEST_CASE("RetainOnTest: an effect that raises the held-out NRMSE is dropped, the rest refitted") {
  Options o;
  m::EffectSet delay;
  delay.pure_delay = m::PureDelay{4.0};
  YChannel y(delay);
  st::ScoreNominal(&y.s(), o);
  // A 30 % gain error on top of the right delay: the test records get worse with it.
  y.Select({{"pure_delay", {4.0}}, {"gain_error", {1.3}}}, {"pure_delay", "gain_error"});
  std::vector<std::string> warnings;
  st::RetainOnTest(&y.s(), y.specs, o, &warnings);
  CHECK(y.s().order == std::vector<std::string>{"pure_delay"});
  CHECK(y.s().sel.count("gain_error") == 0);
  CHECK(y.s().sel.at("pure_delay")[0] == doctest::Approx(4.0).epsilon(0.05));  // refitted alone
  CHECK(Mentions(warnings, "gain_error", "not retained"));

  // The right effect alone is retained, without a warning.
  y.Select({{"pure_delay", {4.0}}}, {"pure_delay"});
  warnings.clear();
  st::RetainOnTest(&y.s(), y.specs, o, &warnings);
  CHECK(y.s().order == std::vector<std::string>{"pure_delay"});
  CHECK(warnings.empty());
}

TEST_CASE("ApplyShrinkRule: a selection short of min_test_shrink_pct is not retained") {
  m::EffectSet delay;
  delay.pure_delay = m::PureDelay{4.0};
  for (const double required : {30.0, 100.0}) {
    CAPTURE(required);
    Options o;
    o.min_test_shrink_pct = required;  // 100 %: no model shrinks a noisy gap that far
    YChannel y(delay);
    st::ScoreNominal(&y.s(), o);
    y.Select({{"pure_delay", {4.0}}}, {"pure_delay"});
    st::EffectResults er;
    st::ScoreSelected(y.s(), y.specs, &er);
    REQUIRE(er.count("pure_delay") == 1);
    CHECK(er.at("pure_delay").selected);
    CHECK(er.at("pure_delay").shrink_pct > 50.0);
    std::vector<std::string> warnings;
    st::ApplyShrinkRule(&y.s(), y.specs, o, &warnings, &er);
    const bool kept = required < 50.0;
    CHECK(y.s().retained == kept);
    CHECK(er.at("pure_delay").selected == kept);
    CHECK(y.s().summary.status == (kept ? "explained" : "unexplained"));
    CHECK(Mentions(warnings, "pure_delay", "not retained") == !kept);
    CHECK(y.s().fin_test.size() == 1);
    if (kept) CHECK(y.s().summary.after_test_pct < 0.5 * y.s().summary.gap_test_pct);
    else CHECK(y.s().summary.after_test_pct == y.s().summary.gap_test_pct);
  }
}

TEST_CASE("supply_ripple's closed form: amplitude and phase per harmonic, none above Nyquist") {
  // A residual with a ripple at 280 Hz sampled at 2 kHz (harmonics at 560 and 840 Hz), harmonic
  // sizes and phases not the library's shape.
  const double dt = 0.0005, f = 280.0;
  const std::size_t n = 8000, first = 400;
  const std::array<double, 6> truth{0.02, -0.01, 0.004, 0.007, -0.003, 0.002};  // s1 c1 s2 c2 s3 c3 [mm]
  auto g = rths::signal::MakeGaussian(5);
  std::vector<double> e(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double w = 2 * M_PI * f * static_cast<double>(k) * dt;
    for (int h = 0; h < 3; ++h) e[k] += truth[2 * h] * std::sin((h + 1) * w) + truth[2 * h + 1] * std::cos((h + 1) * w);
    e[k] += 0.01 * rths::signal::NextGaussian(&g);
  }
  const RippleFit r = FitRipple(e, dt, f, first);
  for (int j = 0; j < 6; ++j) CHECK(std::abs(r.coef[j] - truth[j]) < 6e-4);  // 4 x sigma sqrt(2 / n)
  CHECK(r.FundamentalAmplitude() == doctest::Approx(std::hypot(0.02, 0.01)).epsilon(0.03));
  // The fit leaves the noise: its SSE is about (n - first - 6) sigma^2.
  CHECK(RippleSse(e, dt, f, first) / static_cast<double>(n - first) == doctest::Approx(1e-4).epsilon(0.1));
  // The harmonic spectrum's peak is within one line width (1 / T) of f, not at a harmonic.
  const double peak = RipplePeakHz({e}, {first}, dt, 20.0, 900.0);
  CHECK(std::abs(peak - f) < 1.0 / ((n - first) * dt));
  // Its rate is the sum's exact derivative (against a central difference at a thousandth of dt).
  const double hs = dt / 1000.0;
  for (std::size_t k : {1000u, 3333u}) {
    const double num = (r.Value(1000 * k + 1, hs) - r.Value(1000 * k - 1, hs)) / (2.0 * hs);
    CHECK(r.Rate(k, dt) == doctest::Approx(num).epsilon(1e-4));
  }
  // At 380 Hz the third harmonic (1140 Hz) is above the Nyquist frequency: not fitted (sampled it
  // would fold to 860 Hz, or, nearer fs / 3, down into a test's band).
  const RippleFit high = FitRipple(e, dt, 380.0, first);
  CHECK(high.coef[4] == 0.0);
  CHECK(high.coef[5] == 0.0);
  // AddTo (a rotating phasor, resynchronised every 256 samples) agrees with the direct sines.
  std::vector<double> y(n, 0.0), v(n, 0.0), a(n, 0.0);
  r.AddTo(dt, y, v, a);
  for (std::size_t k : {0u, 255u, 256u, 1000u, 7999u}) {
    CHECK(y[k] == doctest::Approx(r.Value(k, dt)).epsilon(1e-10).scale(0.02));
    CHECK(v[k] == doctest::Approx(r.Rate(k, dt)).epsilon(1e-10).scale(50.0));
    CHECK(a[k] == doctest::Approx(r.Acceleration(k, dt)).epsilon(1e-10).scale(1e5));
  }
}

TEST_CASE("SelectEffects: a pump's ripple is selected as supply_ripple, its frequency to a fraction of its line width") {
  const Options o;
  m::EffectSet ripple;
  ripple.supply_ripple = m::SupplyRipple{173.3, 0.03};
  YChannel y(ripple);
  st::ScoreNominal(&y.s(), o);
  REQUIRE(y.s().structured);
  st::SelectEffects(&y.s(), y.specs, o);
  REQUIRE(y.s().order == std::vector<std::string>{"supply_ripple"});
  CHECK(y.s().sel.at("supply_ripple")[0] == doctest::Approx(173.3).epsilon(1e-4));
  CHECK(y.s().sel.at("supply_ripple")[1] == doctest::Approx(0.03).epsilon(0.05));
  // At the floor afterwards: the ripple's 6 coefficients take no more than their share of noise.
  CHECK(y.s().sse / static_cast<double>(y.s().n_train) <= 1.1 * y.s().var_floor);
  // Its BIC counts the frequency and 2 x 3 coefficients per record.
  CHECK(st::FreeParams(st::SpecOf(y.specs, "supply_ripple"), 2) == 13);
}

TEST_CASE("WeighLostMotion: a play and a friction jump standing in for a short presliding travel are replaced by it") {
  // The miss: a short presliding travel (Dahl stiffness 40 per mm: 0.025 mm) read as
  // backlash + coulomb_friction. Held as the selection, the stage weighs the pair against the one.
  m::EffectSet e;
  e.presliding_friction = m::PreslidingFriction{0.07, 0.025};
  YChannel y(e);
  st::ScoreNominal(&y.s(), Options{});
  REQUIRE(y.s().structured);
  // The pair as a greedy selection would leave it (fitted jointly on the training record).
  st::Params pair = {{"backlash", {0.08}}, {"coulomb_friction", {0.03}}};
  st::RefitAll(y.s().train, y.specs, &pair, y.s().train.Sse(y.s().train.Predict(st::ToSet(y.specs, pair))), 6, Options{});
  y.Select(pair, {"backlash", "coulomb_friction"});
  std::vector<std::string> warnings;
  st::WeighLostMotion(&y.s(), y.specs, Options{}, &warnings);
  REQUIRE(y.s().order == std::vector<std::string>{"presliding_friction"});
  CHECK(Mentions(warnings, "backlash + coulomb_friction replaced by", "presliding_friction"));
  CHECK(y.s().sel.at("presliding_friction")[0] == doctest::Approx(0.07).epsilon(0.15));
  // A true pair of lost-motion effects stays (the single explains it worse by far).
  m::EffectSet two;
  two.backlash = m::Backlash{0.3};
  two.coulomb_friction = m::CoulombFriction{0.15, 0.5};
  YChannel y2(two);
  st::ScoreNominal(&y2.s(), Options{});
  st::Params both = {{"backlash", {0.3}}, {"coulomb_friction", {0.15}}};
  y2.Select(both, {"backlash", "coulomb_friction"});
  std::vector<std::string> w2;
  st::WeighLostMotion(&y2.s(), y2.specs, Options{}, &w2);
  CHECK(y2.s().order == std::vector<std::string>{"backlash", "coulomb_friction"});
}

TEST_CASE("SplitLostMotion: one presliding loss standing in for a dead band beside a short travel is split") {
  // The miss, converse of the above: a valve dead band (0.3 mm) beside a short presliding
  // travel (0.06 mm loss) fitted as one longer presliding loss; the pair's basin is reached from
  // splits of that loss.
  m::EffectSet e;
  e.presliding_friction = m::PreslidingFriction{0.06, 0.025};
  e.command_dead_band = m::CommandDeadBand{0.3};
  YChannel y(e);
  st::ScoreNominal(&y.s(), Options{});
  REQUIRE(y.s().structured);
  // The single as the greedy selection leaves it: its loss the pair's total lost motion.
  st::Params one = {{"presliding_friction", {0.21, 0.1}}};
  st::RefitAll(y.s().train, y.specs, &one, y.s().train.Sse(y.s().train.Predict(st::ToSet(y.specs, one))), 6, Options{});
  y.Select(one, {"presliding_friction"});
  std::vector<std::string> warnings;
  st::SplitLostMotion(&y.s(), y.specs, Options{}, &warnings);
  REQUIRE(y.s().order == std::vector<std::string>{"presliding_friction", "command_dead_band"});
  CHECK(Mentions(warnings, "split into", "command_dead_band"));
  CHECK(y.s().sel.at("command_dead_band")[0] == doctest::Approx(0.3).epsilon(0.2));
  CHECK(y.s().sel.at("presliding_friction")[0] == doctest::Approx(0.06).epsilon(0.3));
  // A presliding friction alone stays one effect.
  m::EffectSet single;
  single.presliding_friction = m::PreslidingFriction{0.2, 0.1};
  YChannel y1(single);
  st::ScoreNominal(&y1.s(), Options{});
  st::Params p1 = {{"presliding_friction", {0.2, 0.1}}};
  st::RefitAll(y1.s().train, y1.specs, &p1, y1.s().train.Sse(y1.s().train.Predict(st::ToSet(y1.specs, p1))), 6, Options{});
  y1.Select(p1, {"presliding_friction"});
  std::vector<std::string> w1;
  st::SplitLostMotion(&y1.s(), y1.specs, Options{}, &w1);
  CHECK(y1.s().order == std::vector<std::string>{"presliding_friction"});
}
