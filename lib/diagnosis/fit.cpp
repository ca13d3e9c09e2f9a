#include "diagnosis/fit.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "diagnosis/candidates.h"
#include "diagnosis/ripple_fit.h"
#include "diagnosis/search.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis::stages {

namespace {

/// The SSE of a candidate's parameter vector, the rest of the set held.
using Objective = std::function<double(const std::vector<double>&)>;

/// One parameter: the grid and golden section over its range, or over a bracket around its
/// current value `cur` (a refit: cur not empty).
double FitOneParam(const ParamSpec& range, bool is_f, const std::vector<double>& cur, const Options& o, const Objective& eval,
                   std::vector<double>* x_out) {
  ParamSpec ps = range;
  int giters = is_f ? tuning::kGoldenItersF : tuning::kGoldenItersY;
  const bool refit = !cur.empty();
  if (refit) {
    ps = BracketAround(range, cur[0], tuning::kRefitBracketFactor, tuning::kRefitBracketFraction, o.refit_grid);
    giters = is_f ? tuning::kRefitGoldenItersF : tuning::kRefitGoldenItersY;
  }
  double best = 0;
  const double x = Minimise1D([&](double x) { return eval({x}); }, ps, giters, &best, refit ? cur : std::vector<double>{});
  *x_out = {x};
  return best;
}

/// The best point of the two parameters' log-spaced grid ({a.lo, b.lo} if none has a finite SSE).
std::vector<double> GridStart(const ParamSpec& a, const ParamSpec& b, const Objective& eval) {
  std::vector<double> v = {a.lo, b.lo};
  double fb = std::numeric_limits<double>::infinity();
  for (int i = 0; i < a.grid; ++i) {
    const double xa = std::clamp(std::exp(std::log(a.lo) + (std::log(a.hi) - std::log(a.lo)) * i / (a.grid - 1)), a.lo, a.hi);
    for (int j = 0; j < b.grid; ++j) {
      const double xb = std::clamp(std::exp(std::log(b.lo) + (std::log(b.hi) - std::log(b.lo)) * j / (b.grid - 1)), b.lo, b.hi);
      const double fv = eval({xa, xb});
      if (fv < fb) fb = fv, v = {xa, xb};
    }
  }
  return v;
}

/// Two parameters (oil_column_resonance), in log coordinates: Nelder-Mead from the grid's best
/// point, or from the current values `cur` (a refit: cur not empty).
double FitTwoParams(const ParamSpec& a, const ParamSpec& b, const std::vector<double>& cur, const Objective& eval,
                    std::vector<double>* x_out) {
  const bool refit = !cur.empty();
  const std::vector<double> v = refit ? cur : GridStart(a, b, eval);
  auto flog = [&](const std::vector<double>& t) {
    const double xa = std::exp(t[0]), xb = std::exp(t[1]);
    if (xa < a.lo || xa > a.hi || xb < b.lo || xb > b.hi) return std::numeric_limits<double>::infinity();
    return eval({xa, xb});
  };
  const double step_a = refit ? tuning::kRefitSimplexStepFirst
                              : tuning::kSimplexStepGridFraction * (std::log(a.hi) - std::log(a.lo)) / (a.grid - 1);
  const double step_b = refit ? tuning::kRefitSimplexStepSecond
                              : tuning::kSimplexStepGridFraction * (std::log(b.hi) - std::log(b.lo)) / (b.grid - 1);
  double best = 0;
  const auto t = NelderMead2(flog, {std::log(v[0]), std::log(v[1])}, {step_a, step_b},
                             refit ? tuning::kRefitSimplexEvals : tuning::kSimplexEvals, &best);
  *x_out = {std::exp(t[0]), std::exp(t[1])};
  return best;
}

/// supply_ripple in closed form (ripple_fit.h): the residual of the set without it; its frequency
/// the peak of the residual's harmonic spectrum (a refit: the current one), refined by golden
/// section on the SSE within one spectral line width 1/T of it (T: the shortest record's span);
/// its amplitude the training records' mean fundamental.
double FitSupplyRipple(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, const std::string& name) {
  const ParamSpec& fr = SpecOf(specs, name).params[0];
  Params q = *p;
  const auto cur = q.find(name);
  const double f_cur = cur == q.end() ? 0.0 : cur->second[0];
  q.erase(name);
  const auto base = ch.Predict(ToSet(specs, q));
  const double dt = ch.recs().front().dt;
  std::vector<std::vector<double>> e(base.size());
  std::vector<std::size_t> first(base.size());
  double span_s = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < base.size(); ++r) {
    const auto meas = ch.Meas(r);
    e[r].resize(meas.size());
    for (std::size_t k = 0; k < meas.size(); ++k) e[r][k] = meas[k] - base[r][k];
    first[r] = ch.recs()[r].first;
    span_s = std::min(span_s, static_cast<double>(meas.size() - first[r]) * dt);
  }
  const double fc = f_cur > 0.0 ? f_cur : RipplePeakHz(e, first, dt, fr.lo, fr.hi);
  const ParamSpec bracket{fr.key, std::max(fr.lo, fc - 1.0 / span_s), std::min(fr.hi, fc + 1.0 / span_s), false,
                          tuning::kRippleBracketGrid};
  auto sse = [&](double f) {
    double s = 0.0;
    for (std::size_t r = 0; r < e.size(); ++r) s += RippleSse(e[r], dt, f, first[r]);
    return s;
  };
  double best = 0.0;
  const double f = Minimise1D(sse, bracket, tuning::kGoldenItersY, &best, {fc});
  double amp = 0.0;
  for (std::size_t r = 0; r < e.size(); ++r) amp += FitRipple(e[r], dt, f, first[r]).FundamentalAmplitude();
  amp /= static_cast<double>(e.size());
  (*p)[name] = {f, std::clamp(amp, SpecOf(specs, name).params[1].lo, SpecOf(specs, name).params[1].hi)};
  return best;
}

}  // namespace

double FitEffect(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, const std::string& name,
                 const Options& o) {
  const auto& spec = SpecOf(specs, name);
  if (name == "damper_scale" || name == "load_cell_inertia") {  // closed form, both together (Channel::Predict)
    if (!p->count(name)) (*p)[name] = {name == "damper_scale" ? 1.0 : 1.0};
    LinearForce lin;
    const auto pred = ch.Predict(ToSet(specs, *p), &lin);
    if (p->count("damper_scale")) (*p)["damper_scale"] = {lin.scale};
    if (p->count("load_cell_inertia")) (*p)["load_cell_inertia"] = {lin.mass_kg};
    return ch.Sse(pred);
  }
  if (name == "supply_ripple") return FitSupplyRipple(ch, specs, p, name);
  const bool refit = p->count(name) > 0;
  const std::vector<double> cur = refit ? (*p)[name] : std::vector<double>{};
  // A non-finite SSE (an overflow on absurd data) ranks last, so the searches below always
  // have a best point and never compare NaNs.
  const Objective eval = [&](const std::vector<double>& v) {
    Params q = *p;
    q[name] = v;
    const double sse = ch.Sse(ch.Predict(ToSet(specs, q)));
    return std::isfinite(sse) ? sse : std::numeric_limits<double>::infinity();
  };
  std::vector<double> x;
  if (spec.params.size() == 2 && spec.params[1].grid < 0) {
    // A parameter and a switch (servovalve_saturation's in_loop): the parameter fitted with the
    // switch at 0 over its range, then at 1 within a factor tuning::kSwitchBracketFactor of that fit
    // (the in-loop form is the slower to simulate, and its vmax is near the other's), the better
    // kept; a refit keeps the switch.
    double best = std::numeric_limits<double>::infinity();
    for (const double sw : refit ? std::vector<double>{cur[1]} : std::vector<double>{0.0, 1.0}) {
      const Objective with = [&](const std::vector<double>& v) { return eval({v[0], sw}); };
      ParamSpec range = spec.params[0];
      std::vector<double> start = refit ? std::vector<double>{cur[0]} : std::vector<double>{};
      if (!refit && sw == 1.0 && !x.empty()) {
        range.lo = std::max(range.lo, x[0] / tuning::kSwitchBracketFactor);
        range.hi = std::min(range.hi, x[0] * tuning::kSwitchBracketFactor);
        range.grid = o.refit_grid;
      }
      std::vector<double> xs;
      const double f = FitOneParam(range, spec.channel == 'f', start, o, with, &xs);
      if (f < best) best = f, x = {xs[0], sw};
      else if (x.empty()) x = {xs[0], sw};
    }
    (*p)[name] = x;
    return best;
  }
  const double best = spec.params.size() == 1
                          ? FitOneParam(spec.params[0], spec.channel == 'f', cur, o, eval, &x)
                          : FitTwoParams(spec.params[0], spec.params[1], cur, eval, &x);
  (*p)[name] = x;
  return best;
}

double RefitAll(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, double sse, int rounds,
                const Options& o) {
  if (p->empty()) return sse;
  for (int r = 0; r < rounds; ++r) {
    double s = sse;
    for (const auto& name : [&] {
           std::vector<std::string> v;
           for (const auto& kv : *p) v.push_back(kv.first);
           return v;
         }()) {
      Params q = *p;
      const double sn = FitEffect(ch, specs, &q, name, o);
      if (sn < s) s = sn, *p = q;
    }
    const bool done = sse - s < tuning::kRefitRelTol * sse;
    sse = s;
    if (done) break;
  }
  return sse;
}

}  // namespace rths::diagnosis::stages
