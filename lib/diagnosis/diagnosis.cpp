#include "diagnosis/diagnosis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/localise.h"
#include "diagnosis/stages.h"
#include "signal/spectral.h"

namespace rths::diagnosis {

// ------------------------------------------------------------------------------------------
// Small arithmetic

double Nrmse(std::span<const double> meas, std::span<const double> pred, std::size_t first) {
  if (meas.size() != pred.size()) throw Error("Nrmse", "lengths differ");
  double se = 0, sm = 0;
  for (std::size_t k = first; k < meas.size(); ++k) {
    const double e = meas[k] - pred[k];
    se += e * e;
    sm += meas[k] * meas[k];
  }
  return sm > 0 ? 100.0 * std::sqrt(se / sm) : std::nan("");
}

double ShrinkPct(double before_pct, double after_pct) { return 100.0 * (1.0 - after_pct / before_pct); }

const ChannelSummary* Result::Channel(const std::string& c) const {
  for (const auto& ch : channels)
    if (ch.channel == c) return &ch;
  return nullptr;
}

bool Options::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  // A real field within [lo, hi] (open ends where lo_open / hi_open).
  auto real = [&](const char* name, double v, double lo, double hi, bool lo_open, bool hi_open) {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (ok) return true;
    const std::string range = std::isinf(hi) ? fmt::format("{} {}", lo_open ? ">" : ">=", lo)
                                             : fmt::format("{}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
    return fail(fmt::format("{} = {}: allowed {}", name, v, range));
  };
  auto integer = [&](const char* name, int v, int lo, int hi) {
    if (v >= lo && v <= hi) return true;
    return fail(fmt::format("{} = {}: allowed [{}, {}]", name, v, lo, hi));
  };
  const double inf = std::numeric_limits<double>::infinity();
  const int imax = std::numeric_limits<int>::max();
  return real("warmup_s", warmup_s, 0.0, inf, false, true) &&
         real("smooth_hz", smooth_hz, 0.0, inf, true, true) &&
         real("max_smooth_cycles_per_sample", max_smooth_cycles_per_sample, 0.0, 0.5, true, true) &&
         real("displacement_only_smooth_factor", displacement_only_smooth_factor, 0.0, inf, true, true) &&
         real("vmax_search_factor", vmax_search_factor, 1.0, inf, false, true) &&
         real("noise_band_lo", noise_band_lo, 0.0, 1.0, false, true) &&
         real("noise_band_split", noise_band_split, noise_band_lo, 1.0, true, true) &&
         real("noise_band_hi", noise_band_hi, noise_band_split, 1.0, true, false) &&
         integer("noise_psd_segment", noise_psd_segment, 8, 1 << 20) &&
         integer("whiteness_lags", whiteness_lags, 1, 10000) &&
         integer("correlation_max_lag", correlation_max_lag, 1, imax - 1) &&
         integer("correlation_lag_divisor", correlation_lag_divisor, 1, imax) &&
         real("none_ratio", none_ratio, 1.0, inf, false, true) &&
         real("min_excess_reduction", min_excess_reduction, 0.0, 1.0, true, true) &&
         real("min_floor_gain", min_floor_gain, 0.0, inf, false, true) &&
         integer("max_effects_per_channel", max_effects_per_channel, 1, imax) &&
         real("min_delay_samples", min_delay_samples, 0.0, inf, false, true) &&
         real("at_bound_fraction", at_bound_fraction, 0.0, 0.5, false, true) &&
         integer("swap_passes", swap_passes, 0, 100) &&
         real("swap_min_gain", swap_min_gain, 0.0, 1.0, false, true) &&
         real("min_test_shrink_pct", min_test_shrink_pct, 0.0, 100.0, false, false) &&
         real("max_test_worsening", max_test_worsening, 0.0, inf, false, true) &&
         integer("golden_iters_y", golden_iters_y, 0, 200) &&
         integer("golden_iters_f", golden_iters_f, 0, 200) &&
         integer("refit_golden_iters_y", refit_golden_iters_y, 0, 200) &&
         integer("refit_golden_iters_f", refit_golden_iters_f, 0, 200) &&
         real("refit_bracket_factor", refit_bracket_factor, 1.0, inf, true, true) &&
         real("refit_bracket_fraction", refit_bracket_fraction, 0.0, 1.0, true, false) &&
         integer("refit_grid", refit_grid, 2, 1000) &&
         integer("simplex_evals", simplex_evals, 3, 100000) &&
         integer("refit_simplex_evals", refit_simplex_evals, 3, 100000) &&
         real("simplex_step_grid_fraction", simplex_step_grid_fraction, 0.0, inf, true, true) &&
         real("refit_simplex_step_first", refit_simplex_step_first, 0.0, inf, true, true) &&
         real("refit_simplex_step_second", refit_simplex_step_second, 0.0, inf, true, true) &&
         real("refit_rel_tol", refit_rel_tol, 0.0, 1.0, false, true) &&
         integer("trial_refit_rounds", trial_refit_rounds, 1, 1000) &&
         integer("refit_rounds", refit_rounds, 1, 1000) &&
         integer("prune_refit_rounds", prune_refit_rounds, 1, 1000) &&
         real("max_condition_samples_pct", max_condition_samples_pct, 0.0, 100.0, true, false) &&
         real("sensor_flat_s", sensor_flat_s, 0.0, inf, true, true);
}

// ------------------------------------------------------------------------------------------
// Effects as parameter vectors

namespace stages {

std::vector<CandidateSpec> Candidates(double dt_s, double data_hi) {
  std::vector<CandidateSpec> out;
  for (const models::EffectInfo& e : models::kEffects) {
    if (!e.diagnosable) continue;
    CandidateSpec c{&e, std::string(e.name), e.channel, {}};
    for (const models::EffectParam& p : e.params()) {
      if (!p.fitted) continue;
      const double hi = p.search_hi_from_data ? data_hi
                        : p.search_hi_per_dt > 0.0 ? p.search_hi_per_dt / dt_s
                                                   : p.search_hi;
      c.params.push_back({std::string(p.key), p.search_lo, hi, p.log, p.grid});
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace stages

namespace {

using stages::CandidateSpec;
using stages::Channel;
using stages::Data;
using stages::ParamSpec;
using stages::Params;
using stages::ToSet;

/// true if a fitted parameter sits on an end of its search range (within `fraction` of the range,
/// Options::at_bound_fraction, in log space for log parameters; a closed-form fit is clipped to its
/// range): the effect's model does not describe the residual there, so it is not selected (e.g. a
/// "resonance" pushed to the highest frequency, a lag at its floor).
bool AtBound(const CandidateSpec& spec, const std::vector<double>& v, double fraction) {
  for (std::size_t j = 0; j < spec.params.size() && j < v.size(); ++j) {
    const auto& p = spec.params[j];
    const double lo = p.log ? std::log(p.lo) : p.lo, hi = p.log ? std::log(p.hi) : p.hi;
    const double x = p.log ? std::log(std::max(v[j], 1e-300)) : v[j];
    const double tol = fraction * (hi - lo);
    if (x <= lo + tol || x >= hi - tol) return true;
  }
  return false;
}

/// true if the set holds pure_delay beside another effect and its tau is shorter than
/// o.min_delay_samples dt: a delay below a sample is a timing convention (a ZOH lags by dt/2, a
/// discrete block and a continuous effect differ by a fraction of a sample), which a sub-sample
/// delay added to the other effect only compensates; it is not a transport delay of its own.
bool SubSampleDelayBeside(const Params& p, double dt, const Options& o) {
  const auto it = p.find("pure_delay");
  return it != p.end() && p.size() >= 2 && 1e-3 * it->second[0] < o.min_delay_samples * dt;
}

/// The damper scale fitted on the training records, if the set has one: on the test records it is
/// held at that value (not refitted in closed form).
std::optional<double> FittedScale(const Params& p) {
  const auto it = p.find("damper_scale");
  return it == p.end() ? std::nullopt : std::optional<double>(it->second[0]);
}

const CandidateSpec& SpecOf(const std::vector<CandidateSpec>& c, const std::string& name) {
  for (const auto& s : c)
    if (name == s.name) return s;
  throw Error("diagnosis", "unknown effect " + name);
}

}  // namespace

void SetEffect(models::EffectSet* set, const std::string& name, const std::map<std::string, double>& p) {
  const models::EffectInfo* info = models::FindEffect(name);
  if (info == nullptr) throw Error("effect", fmt::format("unknown effect \"{}\"", name));
  info->turn_on(*set);  // its defaults
  for (const models::EffectParam& q : info->params()) {
    const auto it = p.find(std::string(q.key));
    if (it != p.end()) {
      *q.field(*set) = it->second;
    } else if (q.required) {
      throw Error("effect " + name, fmt::format("missing parameter {}", q.key));
    }
  }
}

namespace stages {

models::EffectSet ToSet(const std::vector<CandidateSpec>& specs, const Params& p) {
  models::EffectSet set;
  for (const auto& [name, vals] : p) {
    const auto& s = SpecOf(specs, name);
    std::map<std::string, double> m;
    for (std::size_t j = 0; j < s.params.size(); ++j) m[s.params[j].key] = vals[j];
    SetEffect(&set, name, m);
  }
  return set;
}

// ------------------------------------------------------------------------------------------
// The data and the two channels' sums of squares

Data Prepare(const io::RigRecord& r, const Options& o) {
  Data d;
  d.source = r.source;
  d.dt = r.dt_s;
  d.u = r.u_mm;
  d.y = r.y_mm;
  d.f = r.f_kN;
  d.i = r.Command();  // the current, or the voltage of a record without one
  if (o.detrend) {
    for (auto* v : {&d.u, &d.y, &d.f}) {
      const double m = std::accumulate(v->begin(), v->end(), 0.0) / static_cast<double>(v->size());
      for (double& x : *v) x -= m;
    }
  }
  d.first = std::min<std::size_t>(d.size() / 2, static_cast<std::size_t>(std::lround(o.warmup_s / r.dt_s)));
  // The force channel's motion is made once y is diagnosed (ModelAidedMotion).
  return d;
}

}  // namespace stages

namespace {

double Sse(std::span<const double> m, std::span<const double> p, std::size_t first) {
  double s = 0;
  for (std::size_t k = first; k < m.size(); ++k) {
    const double e = m[k] - p[k];
    s += e * e;
  }
  return s;
}
double SumSq(std::span<const double> m, std::size_t first) {
  double s = 0;
  for (std::size_t k = first; k < m.size(); ++k) s += m[k] * m[k];
  return s;
}

}  // namespace

namespace stages {

std::size_t Count(const std::vector<Data>& ds) {
  std::size_t n = 0;
  for (const auto& d : ds) n += d.size() - d.first;
  return n;
}

Channel::Channel(char ch, const std::vector<Data>* recs, const models::LinearServo* servo, const ForcePredictor* fp)
    : ch_(ch), recs_(recs), servo_(servo), fp_(fp) {
  for (const auto& d : *recs_) meas2_ += SumSq(ch_ == 'y' ? d.y : d.f, d.first);
}

std::vector<std::vector<double>> Channel::Predict(const models::EffectSet& set, double* scale_out,
                                                  std::optional<double> fixed_scale) const {
  std::vector<std::vector<double>> out;
  out.reserve(recs_->size());
  if (ch_ == 'y') {
    for (const auto& d : *recs_) out.push_back(PredictDisplacement(*servo_, set, d.u, d.f));
    return out;
  }
  for (const auto& d : *recs_) out.push_back(fp_->PredictUnscaled(d.motion, d.i, set));
  if (set.damper_scale) {
    double s = fixed_scale.value_or(0.0);
    if (!fixed_scale) {
      double num = 0, den = 0;
      for (std::size_t r = 0; r < recs_->size(); ++r) {
        const auto& d = (*recs_)[r];
        for (std::size_t k = d.first; k < d.size(); ++k) {
          num += d.f[k] * out[r][k];
          den += out[r][k] * out[r][k];
        }
      }
      s = den > 0 ? std::clamp(num / den, 0.1, 10.0) : 1.0;
    }
    for (auto& v : out)
      for (double& x : v) x *= s;
    if (scale_out) *scale_out = s;
  }
  return out;
}

double Channel::Sse(const std::vector<std::vector<double>>& pred) const {
  double s = 0;
  for (std::size_t r = 0; r < recs_->size(); ++r) {
    const auto& d = (*recs_)[r];
    s += diagnosis::Sse(ch_ == 'y' ? d.y : d.f, pred[r], d.first);
  }
  return s;
}

double Channel::NrmsePct(double sse) const { return meas2_ > 0 ? 100.0 * std::sqrt(sse / meas2_) : std::nan(""); }

std::span<const double> Channel::Meas(std::size_t r) const { return ch_ == 'y' ? (*recs_)[r].y : (*recs_)[r].f; }

}  // namespace stages

namespace {

/// Golden-section search of a function of one variable on [a, b] (a < b), iters iterations.
double Golden(const std::function<double(double)>& f, double a, double b, int iters, double* fbest) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < iters; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  if (fc < fd) {
    *fbest = fc;
    return c;
  }
  *fbest = fd;
  return d;
}

/// Minimises f over [lo, hi] (log axis if log): a grid of `grid` points, then golden-section
/// between the neighbours of the best grid point. Returns the argmin; *fbest its value.
/// `extra` points (e.g. the current value) are added to the grid.
double Minimise1D(const std::function<double(double)>& f, const ParamSpec& s, int golden_iters, double* fbest,
                  std::vector<double> extra = {}) {
  auto to = [&](double x) { return s.log ? std::log(x) : x; };
  auto from = [&](double t) { return std::clamp(s.log ? std::exp(t) : t, s.lo, s.hi); };
  const double a = to(s.lo), b = to(s.hi);
  std::vector<double> ts;
  for (int j = 0; j < s.grid; ++j) ts.push_back(a + (b - a) * j / (s.grid - 1));
  for (double x : extra)
    if (x >= s.lo && x <= s.hi) ts.push_back(to(x));
  std::sort(ts.begin(), ts.end());
  const double tol = 1e-6 * (b - a);
  ts.erase(std::unique(ts.begin(), ts.end(), [&](double x, double y) { return std::abs(x - y) <= tol; }), ts.end());
  std::vector<double> fs(ts.size());
  std::size_t best = 0;
  for (std::size_t j = 0; j < ts.size(); ++j) {
    fs[j] = f(from(ts[j]));
    if (fs[j] < fs[best]) best = j;
  }
  const double l = ts[best == 0 ? 0 : best - 1], r = ts[std::min(best + 1, ts.size() - 1)];
  double fg = fs[best];
  double tg = ts[best];
  if (r > l && golden_iters > 0) {
    double fv;
    const double t = Golden([&](double t) { return f(from(t)); }, l, r, golden_iters, &fv);
    if (fv < fg) fg = fv, tg = t;
  }
  *fbest = fg;
  return from(tg);
}

/// Nelder-Mead on two variables (the simplex from x0 with steps dx), `evals` function evaluations
/// at most. Returns the best point; *fbest its value.
std::vector<double> NelderMead2(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                                const std::vector<double>& dx, int evals, double* fbest) {
  std::vector<std::vector<double>> p = {x0, {x0[0] + dx[0], x0[1]}, {x0[0], x0[1] + dx[1]}};
  std::vector<double> fv = {f(p[0]), f(p[1]), f(p[2])};
  int n = 3;
  while (n < evals) {
    std::array<int, 3> idx = {0, 1, 2};
    std::sort(idx.begin(), idx.end(), [&](int a, int b) { return fv[a] < fv[b]; });
    const auto& b = p[idx[0]];
    const auto& m = p[idx[1]];
    const auto& w = p[idx[2]];
    const std::vector<double> c = {0.5 * (b[0] + m[0]), 0.5 * (b[1] + m[1])};
    auto at = [&](double t) { return std::vector<double>{c[0] + t * (w[0] - c[0]), c[1] + t * (w[1] - c[1])}; };
    const auto r = at(-1.0);
    const double fr = f(r);
    ++n;
    if (fr < fv[idx[0]]) {
      const auto e = at(-2.0);
      const double fe = f(e);
      ++n;
      if (fe < fr) p[idx[2]] = e, fv[idx[2]] = fe;
      else p[idx[2]] = r, fv[idx[2]] = fr;
    } else if (fr < fv[idx[1]]) {
      p[idx[2]] = r, fv[idx[2]] = fr;
    } else {
      const auto k = at(0.5);
      const double fk = f(k);
      ++n;
      if (fk < fv[idx[2]]) {
        p[idx[2]] = k, fv[idx[2]] = fk;
      } else {  // shrink towards the best
        for (int j : {idx[1], idx[2]}) {
          p[j] = {0.5 * (p[j][0] + b[0]), 0.5 * (p[j][1] + b[1])};
          fv[j] = f(p[j]);
          ++n;
        }
      }
    }
  }
  int best = 0;
  for (int j = 1; j < 3; ++j)
    if (fv[j] < fv[best]) best = j;
  *fbest = fv[best];
  return p[best];
}

/// Fits the parameters of `name` (others in p held) on the channel; returns the SSE and updates
/// p[name]. If p already holds `name` (a refit), the search is local around its value: a bracket
/// of a factor o.refit_bracket_factor (log parameters) or +- o.refit_bracket_fraction of the range
/// (linear ones), o.refit_grid points and golden section (2 parameters: Nelder-Mead in log
/// coordinates from the current point); else the whole range: the grid and golden section
/// (2 parameters: the 2-D grid, then Nelder-Mead).
double FitEffect(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, const std::string& name,
                 const Options& o) {
  const auto& spec = SpecOf(specs, name);
  const bool is_f = spec.channel == 'f';
  if (name == "damper_scale") {
    (*p)[name] = {1.0};
    double s = 1.0;
    const auto pred = ch.Predict(ToSet(specs, *p), &s);
    (*p)[name] = {s};
    return ch.Sse(pred);
  }
  const bool refit = p->count(name) > 0;
  std::vector<double> cur = refit ? (*p)[name] : std::vector<double>{};
  // A non-finite SSE (an overflow on absurd data) ranks last, so the searches below always
  // have a best point and never compare NaNs.
  auto eval = [&](const std::vector<double>& v) {
    Params q = *p;
    q[name] = v;
    const double sse = ch.Sse(ch.Predict(ToSet(specs, q)));
    return std::isfinite(sse) ? sse : std::numeric_limits<double>::infinity();
  };
  double best = 0;
  if (spec.params.size() == 1) {
    ParamSpec ps = spec.params[0];
    int giters = is_f ? o.golden_iters_f : o.golden_iters_y;
    if (refit) {
      const double v = cur[0];
      if (ps.log) {
        ps.lo = std::max(spec.params[0].lo, v / o.refit_bracket_factor);
        ps.hi = std::min(spec.params[0].hi, v * o.refit_bracket_factor);
      } else {
        const double w = o.refit_bracket_fraction * (spec.params[0].hi - spec.params[0].lo);
        ps.lo = std::max(spec.params[0].lo, v - w), ps.hi = std::min(spec.params[0].hi, v + w);
      }
      ps.grid = o.refit_grid;
      giters = is_f ? o.refit_golden_iters_f : o.refit_golden_iters_y;
    }
    const double x = Minimise1D([&](double x) { return eval({x}); }, ps, giters, &best, refit ? cur : std::vector<double>{});
    (*p)[name] = {x};
    return best;
  }
  // Two parameters (oil_column_resonance), in log coordinates.
  const auto& a = spec.params[0];
  const auto& b = spec.params[1];
  std::vector<double> v = cur;
  if (!refit) {
    v = {a.lo, b.lo};  // kept only if no grid point has a finite SSE
    double fb = std::numeric_limits<double>::infinity();
    for (int i = 0; i < a.grid; ++i) {
      const double xa = std::clamp(std::exp(std::log(a.lo) + (std::log(a.hi) - std::log(a.lo)) * i / (a.grid - 1)), a.lo, a.hi);
      for (int j = 0; j < b.grid; ++j) {
        const double xb = std::clamp(std::exp(std::log(b.lo) + (std::log(b.hi) - std::log(b.lo)) * j / (b.grid - 1)), b.lo, b.hi);
        const double fv = eval({xa, xb});
        if (fv < fb) fb = fv, v = {xa, xb};
      }
    }
  }
  auto flog = [&](const std::vector<double>& t) {
    const double xa = std::exp(t[0]), xb = std::exp(t[1]);
    if (xa < a.lo || xa > a.hi || xb < b.lo || xb > b.hi) return std::numeric_limits<double>::infinity();
    return eval({xa, xb});
  };
  const double step_a = refit ? o.refit_simplex_step_first
                              : o.simplex_step_grid_fraction * (std::log(a.hi) - std::log(a.lo)) / (a.grid - 1);
  const double step_b = refit ? o.refit_simplex_step_second
                              : o.simplex_step_grid_fraction * (std::log(b.hi) - std::log(b.lo)) / (b.grid - 1);
  const auto t = NelderMead2(flog, {std::log(v[0]), std::log(v[1])}, {step_a, step_b},
                             refit ? o.refit_simplex_evals : o.simplex_evals, &best);
  (*p)[name] = {std::exp(t[0]), std::exp(t[1])};
  return best;
}

/// Refits every effect of p, coordinate-wise (each with the others held), until a round
/// improves the SSE by less than o.refit_rel_tol of it (at most `rounds` rounds). Returns the SSE.
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
    const bool done = sse - s < o.refit_rel_tol * sse;
    sse = s;
    if (done) break;
  }
  return sse;
}

/// Integrated autocorrelation time of the channel's residual (all records concatenated per
/// record, summed): tau = 1 + 2 sum_{l>=1} r_l up to the first r_l <= 0, at most
/// o.correlation_max_lag lags and n / o.correlation_lag_divisor of a record of n samples.
double IntegratedCorrelationTime(const Channel& ch, const std::vector<std::vector<double>>& pred, const Options& o) {
  std::vector<double> acc;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    if (n < 16) continue;
    // Linear autocorrelation by FFT of the zero-padded residual: R = IDFT(|X|^2); for a real
    // even sequence the inverse DFT is the forward DFT / N.
    std::size_t N = 1;
    while (N < 2 * n) N <<= 1;
    std::vector<double> e(N, 0.0);
    double mean = 0;
    for (std::size_t k = 0; k < n; ++k) mean += meas[d.first + k] - pred[r][d.first + k];
    mean /= static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = meas[d.first + k] - pred[r][d.first + k] - mean;
    const auto X = signal::RealDft(e);
    std::vector<double> p(N);
    for (std::size_t j = 0; j < N; ++j) {
      const auto& x = j <= N / 2 ? X[j] : X[N - j];
      p[j] = std::norm(x);
    }
    const auto R = signal::RealDft(p);
    const std::size_t L = std::min<std::size_t>(static_cast<std::size_t>(o.correlation_max_lag) + 1,
                                                n / static_cast<std::size_t>(o.correlation_lag_divisor));
    if (acc.size() < L) acc.resize(L, 0.0);
    for (std::size_t l = 0; l < L; ++l) acc[l] += R[l].real() / static_cast<double>(N);
  }
  if (acc.empty() || acc[0] <= 0) return 1.0;
  double tau = 1.0;
  for (std::size_t l = 1; l < acc.size(); ++l) {
    const double rl = acc[l] / acc[0];
    if (rl <= 0) break;
    tau += 2.0 * rl;
  }
  return tau;
}

/// Noise floor of a residual set: the level of the residual PSD's plateau above the excitation,
/// sigma^2 = f_Nyq x max(median PSD over [lo, split] f_Nyq, median PSD over [split, hi] f_Nyq)
/// (o.noise_band_lo, o.noise_band_split, o.noise_band_hi), PSDs (Welch, segments of
/// o.noise_psd_segment samples) of the records averaged with weights by their length. For white
/// noise both medians estimate the same level; a sensor's anti-alias filter lowers the upper band
/// (a 4th-order Butterworth at 0.8 f_Nyq: its median to 70 % of the plateau), never the lower one.
double NoiseFloorVar(const Channel& ch, const std::vector<std::vector<double>>& pred, const Options& o) {
  std::vector<double> psd;
  double wsum = 0;
  double nyq = 0;
  std::size_t L = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    L = std::min<std::size_t>(static_cast<std::size_t>(o.noise_psd_segment), n);
    nyq = 0.5 / d.dt;
    std::vector<double> e(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = meas[d.first + k] - pred[r][d.first + k];
    const auto p = signal::WelchPsd(e, d.dt, L);
    if (psd.empty()) psd.assign(p.size(), 0.0);
    if (p.size() != psd.size()) continue;
    for (std::size_t j = 0; j < p.size(); ++j) psd[j] += static_cast<double>(n) * p[j];
    wsum += static_cast<double>(n);
  }
  if (psd.empty() || wsum <= 0) return 0.0;
  const double df = 2.0 * nyq / static_cast<double>(L);
  auto median = [&](double lo, double hi) {
    std::vector<double> band;
    for (std::size_t j = 0; j < psd.size(); ++j) {
      const double f = static_cast<double>(j) * df;
      if (f >= lo * nyq && f <= hi * nyq) band.push_back(psd[j] / wsum);
    }
    if (band.empty()) return 0.0;
    std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2), band.end());
    return band[band.size() / 2];
  };
  return nyq * std::max(median(o.noise_band_lo, o.noise_band_split), median(o.noise_band_split, o.noise_band_hi));
}

/// n sum_{l=1..L} r_l^2 of the residual, L = o.whiteness_lags (records pooled by summing
/// autocovariances).
double Whiteness(const Channel& ch, const std::vector<std::vector<double>>& pred, const Options& o) {
  const int L = o.whiteness_lags;
  std::vector<double> c(L + 1, 0.0);
  double n_tot = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    std::vector<double> e(n);
    double mean = 0;
    for (std::size_t k = 0; k < n; ++k) mean += (e[k] = meas[d.first + k] - pred[r][d.first + k]);
    mean /= static_cast<double>(n);
    for (double& x : e) x -= mean;
    for (int l = 0; l <= L; ++l)
      for (std::size_t k = static_cast<std::size_t>(l); k < n; ++k) c[l] += e[k] * e[k - l];
    n_tot += static_cast<double>(n);
  }
  if (c[0] <= 0) return 0.0;
  double q = 0;
  for (int l = 1; l <= L; ++l) q += (c[l] / c[0]) * (c[l] / c[0]);
  return n_tot * q;
}


std::map<std::string, double> ParamMap(const std::vector<CandidateSpec>& specs, const std::string& name,
                                       const std::vector<double>& v) {
  std::map<std::string, double> m;
  const auto& s = SpecOf(specs, name);
  for (std::size_t j = 0; j < s.params.size(); ++j) m[s.params[j].key] = v[j];
  // The parameters the diagnosis does not fit keep their defaults (coulomb_friction's v_smooth).
  models::EffectSet defaults;
  s.info->turn_on(defaults);
  for (const models::EffectParam& q : s.info->params()) {
    if (!q.fitted) m[std::string(q.key)] = *q.field(defaults);
  }
  return m;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// The stages of one channel (stages.h)

namespace stages {

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
  cs.whiteness = Whiteness(s->test, s->nom_test, o);
  s->structured = cs.floor_ratio > o.none_ratio;
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

void SelectEffects(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o) {
  ChannelState& s = *sp;
  const double dt = s.train.recs().front().dt;
  for (;;) {
    std::optional<Trial> best;
    const double tau = IntegratedCorrelationTime(s.train, s.pred_train, o);
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
      sse = RefitAll(s.train, specs, &t.params, sse, o.trial_refit_rounds, o);  // joint refit
      t.sse = sse;
      const int p = static_cast<int>(spec.params.size());
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
               static_cast<int>(s.order.size()) < o.max_effects_per_channel &&
               !AtBound(spec, t.params.at(spec.name), o.at_bound_fraction) &&
               !(spec.name == "pure_delay" && SubSampleDelayBeside(t.params, dt, o));
      s.last_trial[spec.name] = t;
      if (t.pass && (!best || t.excess_red > best->excess_red)) best = t;
    }
    if (!best) break;
    s.sel = best->params;
    s.order.push_back(best->name);
    s.sel_stats[best->name] = {best->excess_red, best->dbic};
    s.sse = RefitAll(s.train, specs, &s.sel, best->sse, o.refit_rounds, o);
    s.pred_train = s.train.Predict(ToSet(specs, s.sel));
    s.sse = s.train.Sse(s.pred_train);
    s.last_trial.erase(best->name);
  }
}

void SwapEffects(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                 std::vector<std::string>* warnings) {
  ChannelState& s = *sp;
  // E.g. a fast oil-column mode standing in for a delay.
  for (int sw = 0; sw < o.swap_passes && !s.order.empty(); ++sw) {
    double best_sse = s.sse * (1.0 - o.swap_min_gain);
    std::optional<std::pair<std::size_t, Params>> swap;
    std::string swap_in;
    for (std::size_t j = 0; j < s.order.size(); ++j) {
      for (const auto& spec : specs) {
        if (spec.channel != s.ch || s.sel.count(spec.name)) continue;
        Params q = s.sel;
        q.erase(s.order[j]);
        double sq = FitEffect(s.train, specs, &q, spec.name, o);
        sq = RefitAll(s.train, specs, &q, sq, o.refit_rounds, o);
        if (AtBound(spec, q.at(spec.name), o.at_bound_fraction)) continue;  // not an explanation
        if (sq < best_sse) best_sse = sq, swap = std::make_pair(j, q), swap_in = spec.name;
      }
    }
    if (!swap) break;
    warnings->push_back(fmt::format("channel {}: {} replaced by {} (training SSE {:.4g} -> {:.4g})", s.summary.channel,
                                    s.order[swap->first], swap_in, s.sse, best_sse));
    s.sel_stats[swap_in] = s.sel_stats[s.order[swap->first]];
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
          RefitAll(s.train, specs, &q, s.train.Sse(s.train.Predict(ToSet(specs, q))), o.prune_refit_rounds, o);
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
    const double after = s.test.NrmsePct(s.test.Sse(s.test.Predict(ToSet(specs, cum), nullptr, FittedScale(cum))));
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

void ScoreSelected(const ChannelState& s, const std::vector<CandidateSpec>& specs, EffectResults* er) {
  const double before = s.summary.gap_test_pct;
  Params cum;
  for (const auto& name : s.order) {
    cum[name] = s.sel.at(name);
    const auto sset = ToSet(specs, cum);
    const std::optional<double> fixed = FittedScale(cum);
    const auto pt = s.test.Predict(sset, nullptr, fixed);
    const auto ptr = s.train.Predict(sset, nullptr, fixed);
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
    (*er)[name] = e;
  }
}

void ApplyShrinkRule(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o,
                     std::vector<std::string>* warnings, EffectResults* er) {
  ChannelState& s = *sp;
  ChannelSummary& cs = s.summary;
  const double before = cs.gap_test_pct;
  auto fin = s.test.Predict(ToSet(specs, s.sel), nullptr, FittedScale(s.sel));
  cs.after_test_pct = s.test.NrmsePct(s.test.Sse(fin));
  const bool test_structured = cs.floor_ratio_test > o.none_ratio;
  bool retained = !s.order.empty();
  if (retained && test_structured && ShrinkPct(before, cs.after_test_pct) < o.min_test_shrink_pct) {
    warnings->push_back(fmt::format(
        "channel {}: the effects selected on the training records ({}) shrink the test gap by only {:.1f} % "
        "(< {:.0f} %): not retained",
        cs.channel, fmt::join(s.order, ", "), ShrinkPct(before, cs.after_test_pct), o.min_test_shrink_pct));
    for (const auto& n : s.order) (*er)[n].selected = false;
    cs.after_test_pct = before;
    retained = false;
  } else if (retained && !test_structured) {
    warnings->push_back(fmt::format("channel {}: the test records' residual is at the noise floor; the effects "
                                    "were found on the training records only",
                                    cs.channel));
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
  else if (retained) cs.status = "explained";
  else cs.status = "unexplained";
  s.retained = retained;
}

void ScoreCandidates(ChannelState* sp, const std::vector<CandidateSpec>& specs, const Options& o, EffectResults* er) {
  ChannelState& s = *sp;
  const double before = s.summary.gap_test_pct;
  if (!s.retained && !s.order.empty()) {
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
    const auto pt = s.test.Predict(ToSet(specs, t.params), nullptr, FittedScale(t.params));
    EffectResult e;
    e.name = name;
    e.channel = s.summary.channel;
    e.params = ParamMap(specs, name, t.params.at(name));
    e.test_nrmse_after = s.test.NrmsePct(s.test.Sse(pt));
    e.train_nrmse_after = s.train.NrmsePct(t.sse);
    e.shrink_pct = ShrinkPct(before, e.test_nrmse_after);
    e.excess_reduction = t.excess_red;
    e.delta_bic = t.dbic;
    for (const auto& spec : specs)
      if (spec.name == name) e.at_bound = AtBound(spec, t.params.at(name), o.at_bound_fraction);
    (*er)[name] = e;
  }
}

}  // namespace stages

// ------------------------------------------------------------------------------------------
// Around the stages: the records, the candidates, the ranking, the verdict, the localisation

namespace {

using stages::ChannelState;
using stages::EffectResults;

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

/// Upper end of vmax's search range [mm/s]: o.vmax_search_factor x the largest measured velocity
/// of the training records, at most the effect library's limit for vmax (1e9 mm/s; a jump in a
/// record can exceed it).
double VmaxSearchHi(const std::vector<Data>& train, double dt, const Options& o) {
  double vmax_meas = 1.0;
  for (const auto& d : train)
    for (std::size_t k = 1; k < d.size(); ++k) vmax_meas = std::max(vmax_meas, std::abs(d.y[k] - d.y[k - 1]) / dt);
  return std::min(o.vmax_search_factor * vmax_meas, 1e9);
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
  if (!y_ok) {
    const double fc = std::min(o.displacement_only_smooth_factor * o.smooth_hz, o.max_smooth_cycles_per_sample / dt);
    for (auto& d : *train) d.motion = SmoothMotion(d.y, dt, fc);
    for (auto& d : *test) d.motion = SmoothMotion(d.y, dt, fc);
    return;
  }
  // The final model's own velocity and acceleration (exact for the servo) under the smoothed
  // residual's.
  auto motion = [&](const Data& d) {
    std::vector<double> vhat, ahat;
    const std::vector<double> yhat = PredictDisplacement(servo, y.fin_set, d.u, d.f, &vhat, &ahat);
    return ModelAidedMotion(d.y, yhat, vhat, dt, MotionCutoffHz(o, dt), ahat);
  };
  for (auto& d : *train) d.motion = motion(d);
  for (auto& d : *test) d.motion = motion(d);
}

/// res->effects: the verdict's effects in its order, the other candidates by shrink, then the
/// sensor_noise entry (the noise floor, never selected) of each diagnosed channel among the
/// first n_states.
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

/// Where (test records, nominal model): bands, conditions and time windows of every diagnosed
/// channel's residual; the test records' traces if traces is not null.
void LocaliseAndTrace(const std::vector<ChannelState>& st, const std::vector<Data>& test, const Options& o, double dt,
                      Result* res, Traces* traces) {
  for (std::size_t c = 0; c < st.size(); ++c) {
    const auto& s = st[c];
    std::vector<LocaliseInput> li;
    std::vector<SmoothedMotion> motions;
    motions.reserve(test.size());
    for (std::size_t r = 0; r < test.size(); ++r) {
      const auto& d = test[r];
      motions.push_back(d.motion.v_mm_s.empty() ? ModelAidedMotion(d.y, st[0].fin_test[r], {}, dt, MotionCutoffHz(o, dt))
                                                : d.motion);
      LocaliseInput in;
      in.source = d.source;
      in.dt_s = d.dt;
      in.first = d.first;
      in.u = d.u;
      in.meas = s.ch == 'y' ? std::span<const double>(d.y) : std::span<const double>(d.f);
      in.pred = s.nom_test[r];
      in.v = motions.back().v_mm_s;
      in.f_meas = d.f;
      in.i = d.i;
      li.push_back(in);
    }
    if (res->channels[c].diagnosed) {
      const std::size_t first_condition = res->conditions.size();
      Localise(std::string(1, s.ch), li, &res->bands, &res->conditions, &res->time);
      for (std::size_t j = first_condition; j < res->conditions.size(); ++j) {
        Condition& cond = res->conditions[j];
        cond.informative = cond.samples_pct > 0.0 && cond.samples_pct <= o.max_condition_samples_pct;
      }
    }
    if (traces && c == 0) {
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
        tr.y_nom = s.nom_test[r];
        tr.y_fin = s.fin_test[r];
        tr.f_meas = d.f;
        if (st.size() > 1) {
          tr.f_nom = st[1].nom_test[r];
          tr.f_fin = st[1].fin_test[r];
        }
        traces->test.push_back(std::move(tr));
      }
    }
  }
}

}  // namespace

// ------------------------------------------------------------------------------------------

Result Diagnose(const std::vector<io::RigRecord>& train_in, const std::vector<io::RigRecord>& test_in,
                const NominalModel& model, const Options& o, Traces* traces) {
  const auto t_start = std::chrono::steady_clock::now();
  std::string why;
  if (!o.IsValid(&why)) throw Error("diagnosis options", why);
  const double dt = CommonDt(train_in, test_in);
  Result res;
  res.options = o;
  res.dt_s = dt;
  res.model_source = model.source;
  for (const auto& n : model.notes) res.warnings.push_back(n);
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      for (const auto& w : r.warnings) res.warnings.push_back(w);

  std::vector<Data> train, test;
  for (const auto& r : train_in) train.push_back(stages::Prepare(r, o));
  for (const auto& r : test_in) test.push_back(stages::Prepare(r, o));
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

  const auto servo = models::LinearServo::Make(model.actuator, dt);
  std::optional<ForcePredictor> fp;
  if (model.has_damper) fp.emplace(model.damper, model.current_dynamics, dt, model.current_driver);
  const ForcePredictor* fpp = fp ? &*fp : nullptr;
  // A force channel that is all zeros cannot be diagnosed either.
  const bool force_ok = ForceChannelUsable(model, train, &res.warnings);
  const auto specs = stages::Candidates(dt, VmaxSearchHi(train, dt, o));
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
    if (chan == 'f') SetForceMotion(&train, &test, st[0], y_ok, servo, o, dt);
    st.emplace_back(chan, Channel(chan, &train, &servo, fpp), Channel(chan, &test, &servo, fpp));
    auto& s = st.back();
    stages::ScoreNominal(&s, o);
    if (s.ch == 'y' && !y_ok) {
      stages::MarkNotDiagnosed(&s);
      res.channels.push_back(s.summary);
      continue;
    }
    // Progress: selection is most of a channel's time; the other stages share the rest.
    const double base = 10.0 * static_cast<double>(st.size() - 1);  // this channel's index
    const double total = 10.0 * static_cast<double>(chans.size());
    const std::string ch(1, chan);
    if (o.progress) o.progress(base, total, "channel " + ch + ": fitting and selecting effects");
    stages::SelectEffects(&s, specs, o);
    if (o.progress) o.progress(base + 6, total, "channel " + ch + ": swaps and pruning");
    stages::SwapEffects(&s, specs, o, &res.warnings);
    stages::PruneEffects(&s, specs, o, &res.warnings);
    if (o.progress) o.progress(base + 8, total, "channel " + ch + ": held-out test");
    stages::RetainOnTest(&s, specs, o, &res.warnings);
    stages::ScoreSelected(s, specs, &er);
    stages::ApplyShrinkRule(&s, specs, o, &res.warnings, &er);
    if (o.progress) o.progress(base + 9, total, "channel " + ch + ": scoring the other candidates");
    if (s.retained)
      for (const auto& n : s.order) verdict.push_back(n);
    stages::ScoreCandidates(&s, specs, o, &er);
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
  LocaliseAndTrace(st, test, o, dt, &res, traces);
  res.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

// ------------------------------------------------------------------------------------------

std::vector<SensorFault> FindFlatSensors(const io::RigRecord& r, double min_s) {
  std::vector<SensorFault> out;
  const std::size_t n = r.size();
  const auto min_n = static_cast<std::size_t>(std::ceil(min_s / r.dt_s));
  auto scan = [&](const char* channel, const std::vector<double>& x, const std::vector<double>& drive) {
    // A channel constant throughout was not connected (a force column of zeros): said elsewhere.
    if (n == 0 || std::all_of(x.begin(), x.end(), [&](double v) { return v == x[0]; })) return;
    std::size_t a = 0;
    for (std::size_t k = 1; k <= n; ++k) {
      if (k < n && x[k] == x[a]) continue;
      if (k - a >= min_n && k - a >= 2) {  // x[a .. k-1] all equal: does the drive move meanwhile?
        const auto [lo, hi] = std::minmax_element(drive.begin() + static_cast<std::ptrdiff_t>(a),
                                                  drive.begin() + static_cast<std::ptrdiff_t>(k));
        if (*hi > *lo) out.push_back({r.source, channel, r.t_s[a], r.t_s[k - 1], x[a]});
      }
      a = k;
    }
  };
  if (r.y_mm.size() == n && r.u_mm.size() == n) scan("y", r.y_mm, r.u_mm);
  if (r.f_kN.size() == n && r.y_mm.size() == n) scan("f", r.f_kN, r.y_mm);
  return out;
}

nlohmann::json ToJson(const Options& o) {
  return {{"warmup_s", o.warmup_s},
          {"detrend", o.detrend},
          {"smooth_hz", o.smooth_hz},
          {"max_smooth_cycles_per_sample", o.max_smooth_cycles_per_sample},
          {"displacement_only_smooth_factor", o.displacement_only_smooth_factor},
          {"vmax_search_factor", o.vmax_search_factor},
          {"noise_band_lo", o.noise_band_lo},
          {"noise_band_split", o.noise_band_split},
          {"noise_band_hi", o.noise_band_hi},
          {"noise_psd_segment", o.noise_psd_segment},
          {"whiteness_lags", o.whiteness_lags},
          {"correlation_max_lag", o.correlation_max_lag},
          {"correlation_lag_divisor", o.correlation_lag_divisor},
          {"none_ratio", o.none_ratio},
          {"min_excess_reduction", o.min_excess_reduction},
          {"min_floor_gain", o.min_floor_gain},
          {"max_effects_per_channel", o.max_effects_per_channel},
          {"min_delay_samples", o.min_delay_samples},
          {"at_bound_fraction", o.at_bound_fraction},
          {"swap_passes", o.swap_passes},
          {"swap_min_gain", o.swap_min_gain},
          {"min_test_shrink_pct", o.min_test_shrink_pct},
          {"max_test_worsening", o.max_test_worsening},
          {"golden_iters_y", o.golden_iters_y},
          {"golden_iters_f", o.golden_iters_f},
          {"refit_golden_iters_y", o.refit_golden_iters_y},
          {"refit_golden_iters_f", o.refit_golden_iters_f},
          {"refit_bracket_factor", o.refit_bracket_factor},
          {"refit_bracket_fraction", o.refit_bracket_fraction},
          {"refit_grid", o.refit_grid},
          {"simplex_evals", o.simplex_evals},
          {"refit_simplex_evals", o.refit_simplex_evals},
          {"simplex_step_grid_fraction", o.simplex_step_grid_fraction},
          {"refit_simplex_step_first", o.refit_simplex_step_first},
          {"refit_simplex_step_second", o.refit_simplex_step_second},
          {"refit_rel_tol", o.refit_rel_tol},
          {"trial_refit_rounds", o.trial_refit_rounds},
          {"refit_rounds", o.refit_rounds},
          {"prune_refit_rounds", o.prune_refit_rounds},
          {"max_condition_samples_pct", o.max_condition_samples_pct},
          {"sensor_flat_s", o.sensor_flat_s}};
}

nlohmann::json ToJson(const Result& r) {
  using nlohmann::json;
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j;
  const auto* y = r.Channel("y");
  const auto* f = r.Channel("f");
  j["gap"] = {{"nrmse_y_pct", y && y->diagnosed ? num(y->gap_test_pct) : json(nullptr)},
              {"nrmse_f_pct", f && f->diagnosed ? num(f->gap_test_pct) : json(nullptr)}};
  json where;
  where["bands"] = json::array();
  for (const auto& b : r.bands) {
    json o = {{"channel", b.channel}, {"lo_hz", b.lo_hz}, {"hi_hz", b.hi_hz}, {"share_pct", num(b.share_pct)},
              {"signal_share_pct", num(b.signal_share_pct)}, {"rel_residual_pct", num(b.rel_residual_pct)}};
    if (b.coherence >= 0) {
      o["coherence"] = num(b.coherence);
      o["frf_gain_ratio"] = num(b.gain_ratio);
      o["frf_phase_diff_deg"] = num(b.phase_diff_deg);
    }
    where["bands"].push_back(o);
  }
  where["conditions"] = json::array();
  for (const auto& c : r.conditions)
    where["conditions"].push_back({{"channel", c.channel}, {"name", c.name}, {"share_pct", num(c.share_pct)},
                                   {"samples_pct", num(c.samples_pct)}, {"informative", c.informative}});
  where["time"] = json::array();
  for (const auto& t : r.time)
    where["time"].push_back({{"channel", t.channel}, {"record", t.record}, {"t0_s", t.t0_s}, {"t1_s", t.t1_s},
                             {"share_pct", num(t.share_pct)}});
  j["where"] = where;
  j["effects"] = json::array();
  for (const auto& e : r.effects) {
    json o;
    o["name"] = e.name;
    o["channel"] = e.channel;
    json p = json::object();
    for (const auto& [k, v] : e.params) p[k] = num(v);
    o["params"] = p;
    o["nrmse_" + e.channel + "_pct_after"] = num(e.test_nrmse_after);
    o["shrink_pct"] = num(e.shrink_pct);
    o["selected"] = e.selected;
    o["at_bound"] = e.at_bound;
    o["train_nrmse_" + e.channel + "_pct_after"] = num(e.train_nrmse_after);
    if (e.name != "sensor_noise") {
      o["excess_reduction_pct"] = num(100.0 * e.excess_reduction);
      o["delta_bic"] = num(e.delta_bic);
    }
    j["effects"].push_back(o);
  }
  j["verdict"] = r.verdict;
  json ch = json::object();
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      ch[c.channel] = {{"diagnosed", false}, {"status", c.status}};
      continue;
    }
    ch[c.channel] = {{"diagnosed", true},
                     {"status", c.status},
                     {"nrmse_test_pct", num(c.gap_test_pct)},
                     {"nrmse_train_pct", num(c.gap_train_pct)},
                     {"nrmse_test_pct_after", num(c.after_test_pct)},
                     {"noise_floor_rms", num(c.noise_rms)},
                     {"floor_ratio", num(c.floor_ratio)},
                     {"floor_ratio_test", num(c.floor_ratio_test)},
                     {"whiteness_q20", num(c.whiteness)}};
  }
  j["channels"] = ch;
  j["noise_floor"] = {{"y_mm_rms", y && y->diagnosed ? num(y->noise_rms) : json(nullptr)},
                      {"f_kN_rms", f && f->diagnosed ? num(f->noise_rms) : json(nullptr)}};
  j["records"] = {{"train", r.train}, {"test", r.test}};
  j["model"] = r.model_source;
  j["dt_s"] = r.dt_s;
  j["samples"] = r.samples;
  j["runtime_s"] = r.runtime_s;
  j["warnings"] = r.warnings;
  j["sensor_faults"] = json::array();
  for (const auto& sf : r.sensor_faults)
    j["sensor_faults"].push_back({{"record", sf.record}, {"channel", sf.channel}, {"t0_s", sf.t0_s},
                                  {"t1_s", sf.t1_s}, {"value", sf.value}});
  j["options"] = ToJson(r.options);
  return j;
}

namespace {

/// The brief report: the verdict and, per channel, its status and test NRMSE before -> after.
std::string BriefSummary(const Result& r) {
  std::string s = fmt::format("verdict: {}\n", fmt::join(r.verdict, ", "));
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      s += fmt::format("channel {}: not diagnosed\n", c.channel);
      continue;
    }
    s += fmt::format("channel {}: {}, test NRMSE {:.3f} % -> {:.3f} % (shrink {:.1f} %)\n", c.channel, c.status,
                     c.gap_test_pct, c.after_test_pct, ShrinkPct(c.gap_test_pct, c.after_test_pct));
  }
  if (!r.warnings.empty()) s += fmt::format("warnings: {} (in the full report)\n", r.warnings.size());
  return s;
}

}  // namespace

std::string Summary(const Result& r, SummaryDetail detail) {
  if (detail == SummaryDetail::kBrief) return BriefSummary(r);
  std::string s;
  s += fmt::format("model: {}\n", r.model_source);
  s += fmt::format("records: {} training, {} test, dt {} s, {} samples\n", r.train.size(), r.test.size(), r.dt_s, r.samples);
  for (const auto& c : r.channels) {
    if (!c.diagnosed) {
      s += fmt::format("channel {}: not diagnosed\n", c.channel);
      continue;
    }
    s += fmt::format("channel {}: gap {:.3f} % (test; train {:.3f} %), noise floor {:.4g} {}, residual/floor {:.2f} "
                     "-> {}; after: {:.3f} %\n",
                     c.channel, c.gap_test_pct, c.gap_train_pct, c.noise_rms, c.channel == "y" ? "mm" : "kN",
                     c.floor_ratio, c.status, c.after_test_pct);
  }
  for (const auto& ch : {std::string("y"), std::string("f")}) {
    const Band* top = nullptr;
    for (const auto& b : r.bands)
      if (b.channel == ch && (!top || b.share_pct > top->share_pct)) top = &b;
    if (top) s += fmt::format("where ({}): {:.0f}-{:.0f} Hz holds {:.1f} % of the residual", ch, top->lo_hz, top->hi_hz, top->share_pct);
    const Condition* tc = nullptr;
    std::string uninformative;
    for (const auto& c : r.conditions) {
      if (c.channel != ch) continue;
      if (!c.informative) {
        uninformative += fmt::format("{}{} ({:.0f} % of the samples)", uninformative.empty() ? "" : ", ", c.name, c.samples_pct);
        continue;
      }
      if (!tc || c.share_pct / c.samples_pct > tc->share_pct / tc->samples_pct) tc = &c;
    }
    if (tc) s += fmt::format("; {} holds {:.1f} % of it in {:.1f} % of the samples", tc->name, tc->share_pct, tc->samples_pct);
    if (top && !uninformative.empty()) s += fmt::format("; uninformative: {}", uninformative);
    if (top) s += "\n";
  }
  s += "effects (test NRMSE after, shrink):\n";
  std::vector<std::string> pinned;
  for (const auto& e : r.effects) {
    if (e.at_bound && !e.selected) {
      pinned.push_back(e.name);
      continue;
    }
    std::string ps;
    for (const auto& [k, v] : e.params) ps += fmt::format(" {}={:.4g}", k, v);
    // "excess": the training residual's sum of squares above the noise floor (rule (b)).
    const double red_pct = 100.0 * e.excess_reduction;
    s += fmt::format("  {} {:<22} [{}]{}: {:.3f} %, shrink {:.1f} % (training: {} {:.0f} % of the residual above noise)\n",
                     e.selected ? "*" : " ", e.name, e.channel, ps, e.test_nrmse_after, e.shrink_pct,
                     red_pct >= 0.0 ? "removes" : "adds", std::abs(red_pct));
  }
  if (!pinned.empty()) {
    s += fmt::format("  (not shown: {} fitted to an end of the search range, so not a description of the residual; "
                     "diagnosis.json has them)\n",
                     fmt::join(pinned, ", "));
  }
  s += fmt::format("verdict: {}\n", fmt::join(r.verdict, ", "));
  for (const auto& w : r.warnings) s += "warning: " + w + "\n";
  s += fmt::format("runtime: {:.2f} s\n", r.runtime_s);
  return s;
}

}  // namespace rths::diagnosis
