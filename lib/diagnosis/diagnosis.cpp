#include "diagnosis/diagnosis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <numeric>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "core/error.h"
#include "diagnosis/localise.h"
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

// ------------------------------------------------------------------------------------------
// Effects as parameter vectors

namespace {

struct ParamSpec {
  const char* key;
  double lo, hi;
  bool log;
  int grid;
};
struct CandidateSpec {
  const char* name;
  char channel;  // 'y' or 'f'
  std::vector<ParamSpec> params;
};

/// The fitted parameters and their search ranges (docs/diagnosis.md "Fitting"). vmax's upper end
/// is set per data set (twice the largest measured velocity).
std::vector<CandidateSpec> Candidates(double dt_s, double vmax_hi) {
  return {
      {"pure_delay", 'y', {{"tau_ms", 0.0, 40.0, false, 81}}},
      {"gain_error", 'y', {{"gain", 0.5, 2.0, true, 41}}},
      {"load_coupling", 'y', {{"compliance_mm_per_kN", 0.0, 0.2, false, 81}}},  // yields: c >= 0
      {"oil_column_resonance", 'y', {{"f_hz", 2.0, 0.4 / dt_s, true, 40}, {"zeta", 0.02, 1.5, true, 10}}},
      {"coulomb_friction", 'y', {{"loss_mm", 1e-3, 10.0, true, 31}}},
      {"backlash", 'y', {{"gap_mm", 1e-3, 10.0, true, 31}}},
      {"servovalve_saturation", 'y', {{"vmax_mm_per_s", 1.0, vmax_hi, true, 31}}},
      {"current_lag", 'f', {{"tau_ms", 0.5, 1000.0, true, 12}}},
      {"damper_scale", 'f', {{"scale", 0.1, 10.0, true, 0}}},  // closed form
  };
}

using Params = std::map<std::string, std::vector<double>>;  // effect name -> values (spec order)

/// true if a fitted parameter sits on an end of its search range (within 0.1 % of the range, in
/// log space for log parameters; a closed-form fit is clipped to its range): the effect's model does not describe the residual there, so it
/// is not selected (e.g. a "resonance" pushed to the highest frequency, a lag at its floor).
bool AtBound(const CandidateSpec& spec, const std::vector<double>& v) {
  for (std::size_t j = 0; j < spec.params.size() && j < v.size(); ++j) {
    const auto& p = spec.params[j];
    const double lo = p.log ? std::log(p.lo) : p.lo, hi = p.log ? std::log(p.hi) : p.hi;
    const double x = p.log ? std::log(std::max(v[j], 1e-300)) : v[j];
    const double tol = 1e-3 * (hi - lo);
    if (x <= lo + tol || x >= hi - tol) return true;
  }
  return false;
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
  auto get = [&](const char* key) {
    const auto it = p.find(key);
    if (it == p.end()) throw Error("effect " + name, fmt::format("missing parameter {}", key));
    return it->second;
  };
  if (name == "pure_delay") set->pure_delay = models::PureDelay{get("tau_ms")};
  else if (name == "gain_error") set->gain_error = models::GainError{get("gain")};
  else if (name == "load_coupling") set->load_coupling = models::LoadCoupling{get("compliance_mm_per_kN")};
  else if (name == "oil_column_resonance") set->oil_column_resonance = models::OilColumnResonance{get("f_hz"), get("zeta")};
  else if (name == "coulomb_friction") {
    models::CoulombFriction c;
    c.loss_mm = get("loss_mm");
    if (p.count("v_smooth_mm_s")) c.v_smooth_mm_s = p.at("v_smooth_mm_s");
    set->coulomb_friction = c;
  } else if (name == "backlash") set->backlash = models::Backlash{get("gap_mm")};
  else if (name == "servovalve_saturation") set->servovalve_saturation = models::ServovalveSaturation{get("vmax_mm_per_s")};
  else if (name == "current_lag") set->current_lag = models::CurrentLag{get("tau_ms")};
  else if (name == "damper_scale") set->damper_scale = models::DamperScale{get("scale")};
  else if (name == "sensor_noise") {
    models::SensorNoise s;
    if (p.count("rms_y_mm")) s.rms_y_mm = p.at("rms_y_mm");
    if (p.count("rms_f_kN")) s.rms_f_kN = p.at("rms_f_kN");
    set->sensor_noise = s;
  } else {
    throw Error("effect", fmt::format("unknown effect \"{}\"", name));
  }
}

namespace {

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

struct Data {
  std::string source;
  double dt = 0;
  std::vector<double> u, y, f, i;
  SmoothedMotion motion;
  std::size_t first = 0;
  std::size_t size() const { return u.size(); }
};

Data Prepare(const io::RigRecord& r, const Options& o) {
  Data d;
  d.source = r.source;
  d.dt = r.dt_s;
  d.u = r.u_mm;
  d.y = r.y_mm;
  d.f = r.f_kN;
  d.i = r.i_A;
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
std::size_t Count(const std::vector<Data>& ds) {
  std::size_t n = 0;
  for (const auto& d : ds) n += d.size() - d.first;
  return n;
}

/// Evaluates a channel's predictions for an effect set over a set of records.
class Channel {
 public:
  Channel(char ch, const std::vector<Data>* recs, const models::LinearServo* servo, const ForcePredictor* fp)
      : ch_(ch), recs_(recs), servo_(servo), fp_(fp) {
    for (const auto& d : *recs_) meas2_ += SumSq(ch_ == 'y' ? d.y : d.f, d.first);
  }
  /// Predictions per record. For 'f' with damper_scale in the set, the scale is replaced by the
  /// least-squares one over these records (closed form) and written back to *scale_out.
  std::vector<std::vector<double>> Predict(const models::EffectSet& set, double* scale_out = nullptr,
                                           std::optional<double> fixed_scale = std::nullopt) const {
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
  double Sse(const std::vector<std::vector<double>>& pred) const {
    double s = 0;
    for (std::size_t r = 0; r < recs_->size(); ++r) {
      const auto& d = (*recs_)[r];
      s += diagnosis::Sse(ch_ == 'y' ? d.y : d.f, pred[r], d.first);
    }
    return s;
  }
  double NrmsePct(double sse) const { return meas2_ > 0 ? 100.0 * std::sqrt(sse / meas2_) : std::nan(""); }
  const std::vector<Data>& recs() const { return *recs_; }
  std::span<const double> Meas(std::size_t r) const { return ch_ == 'y' ? (*recs_)[r].y : (*recs_)[r].f; }

 private:
  char ch_;
  const std::vector<Data>* recs_;
  const models::LinearServo* servo_;
  const ForcePredictor* fp_;
  double meas2_ = 0;
};

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
/// of a factor 1.3 (log parameters) or +-5 % of the range (linear ones), 5 points and golden
/// section (2 parameters: Nelder-Mead in log coordinates from the current point); else the whole
/// range: the grid and golden section (2 parameters: the 2-D grid, then Nelder-Mead).
double FitEffect(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, const std::string& name) {
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
    int giters = is_f ? 12 : 24;
    if (refit) {
      const double v = cur[0];
      if (ps.log) {
        ps.lo = std::max(spec.params[0].lo, v / 1.3), ps.hi = std::min(spec.params[0].hi, v * 1.3);
      } else {
        const double w = 0.05 * (spec.params[0].hi - spec.params[0].lo);
        ps.lo = std::max(spec.params[0].lo, v - w), ps.hi = std::min(spec.params[0].hi, v + w);
      }
      ps.grid = 5;
      giters = is_f ? 8 : 14;
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
  const double step_a = refit ? 0.05 : 0.5 * (std::log(a.hi) - std::log(a.lo)) / (a.grid - 1);
  const double step_b = refit ? 0.1 : 0.5 * (std::log(b.hi) - std::log(b.lo)) / (b.grid - 1);
  const auto t = NelderMead2(flog, {std::log(v[0]), std::log(v[1])}, {step_a, step_b}, refit ? 24 : 48, &best);
  (*p)[name] = {std::exp(t[0]), std::exp(t[1])};
  return best;
}

/// Refits every effect of p, coordinate-wise (each with the others held), until a round
/// improves the SSE by less than 1e-4 of it (at most `rounds` rounds). Returns the SSE.
double RefitAll(const Channel& ch, const std::vector<CandidateSpec>& specs, Params* p, double sse, int rounds = 3) {
  if (p->empty()) return sse;
  for (int r = 0; r < rounds; ++r) {
    double s = sse;
    for (const auto& name : [&] {
           std::vector<std::string> v;
           for (const auto& kv : *p) v.push_back(kv.first);
           return v;
         }()) {
      Params q = *p;
      const double sn = FitEffect(ch, specs, &q, name);
      if (std::getenv("RTHS_DIAG_DEBUG")) std::fprintf(stderr, "  refit %s: %g -> %g (%g)\n", name.c_str(), s, sn, q[name][0]);
      if (sn < s) s = sn, *p = q;
    }
    const bool done = sse - s < 1e-4 * sse;
    sse = s;
    if (done) break;
  }
  return sse;
}

/// Integrated autocorrelation time of the channel's residual (all records concatenated per
/// record, summed): tau = 1 + 2 sum_{l>=1} r_l up to the first r_l <= 0, at most 2000 lags.
double IntegratedCorrelationTime(const Channel& ch, const std::vector<std::vector<double>>& pred) {
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
    const std::size_t L = std::min<std::size_t>(2001, n / 4);
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

/// Noise floor of a residual set: sigma^2 = median PSD over [0.5, 0.95] f_Nyq x f_Nyq, PSDs of
/// the records averaged with weights by their length.
double NoiseFloorVar(const Channel& ch, const std::vector<std::vector<double>>& pred) {
  std::vector<double> psd;
  double wsum = 0;
  double nyq = 0;
  std::size_t L = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto& d = ch.recs()[r];
    const auto meas = ch.Meas(r);
    const std::size_t n = d.size() - d.first;
    L = std::min<std::size_t>(256, n);
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
  std::vector<double> top;
  const double df = 2.0 * nyq / static_cast<double>(L);
  for (std::size_t j = 0; j < psd.size(); ++j) {
    const double f = static_cast<double>(j) * df;
    if (f >= 0.5 * nyq && f <= 0.95 * nyq) top.push_back(psd[j] / wsum);
  }
  if (top.empty()) return 0.0;
  std::nth_element(top.begin(), top.begin() + static_cast<std::ptrdiff_t>(top.size() / 2), top.end());
  return top[top.size() / 2] * nyq;
}

/// n sum_{l=1..20} r_l^2 of the residual (records pooled by summing autocovariances).
double Whiteness(const Channel& ch, const std::vector<std::vector<double>>& pred) {
  const int L = 20;
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
  if (name == "coulomb_friction") m["v_smooth_mm_s"] = models::CoulombFriction{}.v_smooth_mm_s;
  return m;
}

}  // namespace

// ------------------------------------------------------------------------------------------

Result Diagnose(const std::vector<io::RigRecord>& train_in, const std::vector<io::RigRecord>& test_in,
                const NominalModel& model, const Options& o, Traces* traces) {
  const auto t_start = std::chrono::steady_clock::now();
  if (train_in.empty()) throw Error("--train", "at least one training record is needed");
  if (test_in.empty()) throw Error("--test", "at least one test record is needed");
  const double dt = train_in[0].dt_s;
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      if (std::abs(r.dt_s - dt) > 1e-9 * dt)
        throw Error(r.source, fmt::format("dt_s {} differs from the first training record's {} (one dt per diagnosis)",
                                          r.dt_s, dt));
  Result res;
  res.options = o;
  res.dt_s = dt;
  res.model_source = model.source;
  for (const auto& n : model.notes) res.warnings.push_back(n);
  for (const auto* set : {&train_in, &test_in})
    for (const auto& r : *set)
      for (const auto& w : r.warnings) res.warnings.push_back(w);

  std::vector<Data> train, test;
  for (const auto& r : train_in) train.push_back(Prepare(r, o));
  for (const auto& r : test_in) test.push_back(Prepare(r, o));
  for (const auto& d : train) res.train.push_back(d.source);
  for (const auto& d : test) res.test.push_back(d.source);
  res.samples = Count(train) + Count(test);

  const auto servo = models::LinearServo::Make(model.actuator, dt);
  std::optional<ForcePredictor> fp;
  if (model.has_damper) fp.emplace(model.damper, model.current_dynamics, dt);
  // A force channel that is all zeros cannot be diagnosed either.
  bool force_ok = model.has_damper;
  if (force_ok) {
    double s = 0;
    for (const auto& d : train) s += SumSq(d.f, d.first);
    if (!(s > 0)) {
      force_ok = false;
      res.warnings.push_back("the training records' force is zero: the force channel is not diagnosed");
    }
  } else {
    res.warnings.push_back("the model has no damper part: the force channel is not diagnosed");
  }
  double vmax_meas = 1.0;
  for (const auto& d : train)
    for (std::size_t k = 1; k < d.size(); ++k) vmax_meas = std::max(vmax_meas, std::abs(d.y[k] - d.y[k - 1]) / dt);
  // At most the effect library's limit for vmax (1e9 mm/s; a jump in a record can exceed it).
  const auto specs = Candidates(dt, std::min(2.0 * vmax_meas, 1e9));
  // A displacement-only test (u = y in every record, e.g. the UTFSM damper tests) has no
  // displacement channel to diagnose: predicting y from u would only show the model's own lag.
  bool y_ok = false;
  for (const auto* set : {&train, &test})
    for (const auto& d : *set) y_ok |= d.u != d.y;
  if (!y_ok)
    res.warnings.push_back("u = y in every record (a displacement-only test): the displacement channel is not diagnosed");

  // The channels are diagnosed one after the other: y first, then f, whose motion input is the
  // measured y seen through y's final model (ModelAidedMotion).
  std::vector<char> chans = {'y'};
  if (force_ok) chans.push_back('f');
  struct ChState {
    ChState(char c, Channel tr, Channel te) : ch(c), train(std::move(tr)), test(std::move(te)) {}
    char ch;
    Channel train, test;
    Params sel;                       // selected effects and their parameters
    std::vector<std::string> order;   // selected names in order
    double sse = 0;                   // training SSE with sel
    double var_floor = 0;             // sigma^2
    std::size_t n_train = 0;
    bool structured = false;
    std::vector<std::vector<double>> pred_train;  // with sel
    std::vector<std::vector<double>> nom_test;    // nominal, test
    std::vector<std::vector<double>> fin_test;    // final (retained effects), test
    std::vector<std::vector<double>> pred_train_fin;  // final (retained effects), training
    Params keep;                      // retained effects
  };
  std::vector<std::unique_ptr<ChState>> st;
  std::map<std::string, EffectResult> er;
  std::vector<std::string> verdict;
  const ForcePredictor* fpp = fp ? &*fp : nullptr;
  for (char chan : chans) {
    if (chan == 'f') {
      // The motion of the damper: y's final model plus the zero-phase-smoothed residual.
      const auto& ys = *st[0];
      if (!y_ok) {
        // No displacement model to lean on (u = y): the measured y, zero-phase smoothed at a
        // cutoff above the excitation (4 x smooth_hz, at most 0.45 / dt).
        const double fc = std::min(4.0 * o.smooth_hz, 0.45 / dt);
        for (auto& d : train) d.motion = SmoothMotion(d.y, dt, fc);
        for (auto& d : test) d.motion = SmoothMotion(d.y, dt, fc);
      } else {
        for (std::size_t r = 0; r < train.size(); ++r)
          train[r].motion = ModelAidedMotion(train[r].y, ys.pred_train_fin[r], dt, std::min(o.smooth_hz, 0.45 / dt));
        for (std::size_t r = 0; r < test.size(); ++r)
          test[r].motion = ModelAidedMotion(test[r].y, ys.fin_test[r], dt, std::min(o.smooth_hz, 0.45 / dt));
      }
    }
    st.push_back(std::make_unique<ChState>(chan, Channel(chan, &train, &servo, fpp), Channel(chan, &test, &servo, fpp)));
    auto& s = *st.back();
    // --- nominal residuals, noise floor, gap
    ChannelSummary cs;
    cs.channel = std::string(1, s.ch);
    cs.diagnosed = true;
    s.pred_train = s.train.Predict({});
    s.nom_test = s.test.Predict({});
    s.sse = s.train.Sse(s.pred_train);
    s.n_train = Count(train);
    const double sse_test = s.test.Sse(s.nom_test);
    for (const auto& [sse, set] : {std::pair{s.sse, &train}, std::pair{sse_test, &test}}) {
      if (std::isfinite(sse)) continue;
      std::string names;
      for (const auto& d : *set) names += (names.empty() ? "" : ", ") + d.source;
      throw Error(names, fmt::format("the nominal model's {} residual is not finite: the model diverged on these "
                                     "records (is dt_s = {} s fine enough for it?) or a value is too large for "
                                     "the arithmetic",
                                     s.ch == 'y' ? "displacement" : "force", dt));
    }
    cs.gap_train_pct = s.train.NrmsePct(s.sse);
    cs.gap_test_pct = s.test.NrmsePct(sse_test);
    const double v_tr = NoiseFloorVar(s.train, s.pred_train), v_te = NoiseFloorVar(s.test, s.nom_test);
    const double n_tr = static_cast<double>(Count(train)), n_te = static_cast<double>(Count(test));
    s.var_floor = (v_tr * n_tr + v_te * n_te) / (n_tr + n_te);
    cs.noise_rms = std::sqrt(s.var_floor);
    const double ms = (s.sse + sse_test) / (n_tr + n_te);
    cs.floor_ratio = s.var_floor > 0 ? ms / s.var_floor : std::numeric_limits<double>::infinity();
    cs.floor_ratio_test = s.var_floor > 0 ? (sse_test / n_te) / s.var_floor : std::numeric_limits<double>::infinity();
    cs.whiteness = Whiteness(s.test, s.nom_test);
    s.structured = cs.floor_ratio > o.none_ratio;
    if (s.ch == 'y' && !y_ok) {
      cs.diagnosed = false;
      cs.status = "not diagnosed";
      s.structured = false;
      s.fin_test = s.nom_test;
      s.pred_train_fin = s.pred_train;
      res.channels.push_back(cs);
      continue;
    }
    const double sse_nom = s.sse;
    const double excess_nom = sse_nom - static_cast<double>(s.n_train) * s.var_floor;

    // --- greedy selection on the training records
    struct Trial {
      std::string name;
      Params params;  // the channel's whole set with this candidate
      double sse = 0, excess_red = 0, dbic = 0, marginal_red = 0;
      bool pass = false;
    };
    std::map<std::string, Trial> last_trial;  // latest trial of every candidate
    std::map<std::string, std::pair<double, double>> sel_stats;  // selected: (excess reduction, dBIC) when added
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
        double sse = FitEffect(s.train, specs, &t.params, spec.name);
        sse = RefitAll(s.train, specs, &t.params, sse, 2);  // joint refit, two coordinate rounds
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
                 !AtBound(spec, t.params.at(spec.name));
        last_trial[spec.name] = t;
        if (t.pass && (!best || t.excess_red > best->excess_red)) best = t;
      }
      if (!best) break;
      s.sel = best->params;
      s.order.push_back(best->name);
      sel_stats[best->name] = {best->excess_red, best->dbic};
      s.sse = RefitAll(s.train, specs, &s.sel, best->sse, 6);
      s.pred_train = s.train.Predict(ToSet(specs, s.sel));
      s.sse = s.train.Sse(s.pred_train);
      last_trial.erase(best->name);
    }
    // Swaps: an effect of the set replaced by another candidate (fitted, then the set refitted)
    // when that lowers the training SSE by more than 0.1 % (e.g. a fast oil-column mode
    // standing in for a delay); then pruning: an effect whose own share of the set's excess
    // (the set refitted without it) is below min_excess_reduction is removed.
    for (int sw = 0; sw < 2 && !s.order.empty(); ++sw) {
      double best_sse = s.sse * (1.0 - 1e-3);
      std::optional<std::pair<std::size_t, Params>> swap;
      std::string swap_in;
      for (std::size_t j = 0; j < s.order.size(); ++j) {
        for (const auto& spec : specs) {
          if (spec.channel != s.ch || s.sel.count(spec.name)) continue;
          Params q = s.sel;
          q.erase(s.order[j]);
          double sq = FitEffect(s.train, specs, &q, spec.name);
          sq = RefitAll(s.train, specs, &q, sq, 6);
          if (AtBound(spec, q.at(spec.name))) continue;  // not an explanation (AtBound)
          if (std::getenv("RTHS_DIAG_DEBUG")) std::fprintf(stderr, "swap %s -> %s: %g (now %g)\n", s.order[j].c_str(), spec.name, sq, s.sse);
          if (sq < best_sse) best_sse = sq, swap = std::make_pair(j, q), swap_in = spec.name;
        }
      }
      if (!swap) break;
      res.warnings.push_back(fmt::format("channel {}: {} replaced by {} (training SSE {:.4g} -> {:.4g})", cs.channel,
                                         s.order[swap->first], swap_in, s.sse, best_sse));
      sel_stats[swap_in] = sel_stats[s.order[swap->first]];
      s.order[swap->first] = swap_in;
      s.sel = swap->second;
      s.sse = best_sse;
    }
    for (bool pruned = true; pruned && s.order.size() > 1;) {
      pruned = false;
      double least = o.min_excess_reduction;
      std::optional<std::pair<std::size_t, Params>> drop;
      double drop_sse = 0;
      for (std::size_t j = 0; j < s.order.size(); ++j) {
        Params q = s.sel;
        q.erase(s.order[j]);
        const double sq = RefitAll(s.train, specs, &q, s.train.Sse(s.train.Predict(ToSet(specs, q))), 2);
        const double ex = sq - static_cast<double>(s.n_train) * s.var_floor;
        const double share = ex > 0 ? (sq - s.sse) / ex : 0.0;
        if (share < least) least = share, drop = std::make_pair(j, q), drop_sse = sq;
      }
      if (drop) {
        res.warnings.push_back(fmt::format("channel {}: {} pruned (its own share of the excess {:.0f} % < {:.0f} %)", cs.channel,
                                           s.order[drop->first], 100.0 * least, 100.0 * o.min_excess_reduction));
        s.order.erase(s.order.begin() + static_cast<std::ptrdiff_t>(drop->first));
        s.sel = drop->second;
        s.sse = drop_sse;
        pruned = true;
      }
    }
    s.pred_train = s.train.Predict(ToSet(specs, s.sel));
    s.sse = s.train.Sse(s.pred_train);

    // --- test scores; the 30 % rule
    const double before = cs.gap_test_pct;
    // An effect whose addition (in the order of selection) makes the test NRMSE worse by more
    // than max_test_worsening is not retained (a fit of training misfit that does not carry
    // over); the rest are refitted on the training records without it.
    {
      Params cum;
      double prev = before;
      std::vector<std::string> kept;
      for (const auto& name : s.order) {
        cum[name] = s.sel.at(name);
        const double after = s.test.NrmsePct(s.test.Sse(s.test.Predict(ToSet(specs, cum), nullptr, FittedScale(cum))));
        if (after > prev * (1.0 + o.max_test_worsening)) {
          res.warnings.push_back(fmt::format("channel {}: {} (selected on the training records) raises the test NRMSE "
                                             "from {:.4g} % to {:.4g} %: not retained",
                                             cs.channel, name, prev, after));
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
        s.sse = RefitAll(s.train, specs, &s.sel, s.train.Sse(s.train.Predict(ToSet(specs, s.sel))), 6);
        s.pred_train = s.train.Predict(ToSet(specs, s.sel));
      }
    }
    Params cum;
    for (const auto& name : s.order) {
      cum[name] = s.sel.at(name);
      const auto sset = ToSet(specs, cum);
      const std::optional<double> fixed = FittedScale(cum);
      const auto pt = s.test.Predict(sset, nullptr, fixed);
      const auto ptr = s.train.Predict(sset, nullptr, fixed);
      EffectResult e;
      e.name = name;
      e.channel = cs.channel;
      e.params = ParamMap(specs, name, s.sel.at(name));
      e.test_nrmse_after = s.test.NrmsePct(s.test.Sse(pt));
      e.train_nrmse_after = s.train.NrmsePct(s.train.Sse(ptr));
      e.shrink_pct = ShrinkPct(before, e.test_nrmse_after);
      e.selected = true;
      e.excess_reduction = sel_stats[name].first;
      e.delta_bic = sel_stats[name].second;
      er[name] = e;
    }
    auto fin = s.test.Predict(ToSet(specs, s.sel), nullptr, FittedScale(s.sel));
    cs.after_test_pct = s.test.NrmsePct(s.test.Sse(fin));
    const bool test_structured = cs.floor_ratio_test > o.none_ratio;
    bool retained = !s.order.empty();
    if (retained && test_structured && ShrinkPct(before, cs.after_test_pct) < o.min_test_shrink_pct) {
      res.warnings.push_back(fmt::format(
          "channel {}: the effects selected on the training records ({}) shrink the test gap by only {:.1f} % "
          "(< {:.0f} %): not retained",
          cs.channel, fmt::join(s.order, ", "), ShrinkPct(before, cs.after_test_pct), o.min_test_shrink_pct));
      for (const auto& n : s.order) er[n].selected = false;
      cs.after_test_pct = before;
      retained = false;
    } else if (retained && !test_structured) {
      res.warnings.push_back(fmt::format("channel {}: the test records' residual is at the noise floor; the effects "
                                         "were found on the training records only",
                                         cs.channel));
    }
    if (retained) {
      s.keep = s.sel;
      s.fin_test = std::move(fin);
      s.pred_train_fin = s.pred_train;
      for (const auto& n : s.order) verdict.push_back(n);
    } else {
      s.fin_test = s.nom_test;
      s.pred_train_fin = s.train.Predict({});
    }
    if (!s.structured) cs.status = "noise";
    else if (retained) cs.status = "explained";
    else cs.status = "unexplained";
    // Candidates not selected: their latest trial (fitted on top of the selected ones). If the
    // selection was not retained, every candidate is refitted alone on the nominal model so that
    // its numbers stand on their own.
    if (!retained && !s.order.empty()) {
      for (auto& [name, t] : last_trial) {
        Params q;
        t.sse = FitEffect(s.train, specs, &q, name);
        t.params = q;
        t.excess_red = excess_nom > 0 ? (sse_nom - t.sse) / excess_nom : 0.0;
        t.dbic = std::nan("");
      }
      for (const auto& name : s.order) {
        Trial t;
        t.name = name;
        t.sse = FitEffect(s.train, specs, &t.params, name);
        t.excess_red = excess_nom > 0 ? (sse_nom - t.sse) / excess_nom : 0.0;
        t.dbic = std::nan("");
        last_trial[name] = t;
        er.erase(name);
      }
    }
    for (const auto& [name, t] : last_trial) {
      if (er.count(name)) continue;
      const auto pt = s.test.Predict(ToSet(specs, t.params), nullptr, FittedScale(t.params));
      EffectResult e;
      e.name = name;
      e.channel = cs.channel;
      e.params = ParamMap(specs, name, t.params.at(name));
      e.test_nrmse_after = s.test.NrmsePct(s.test.Sse(pt));
      e.train_nrmse_after = s.train.NrmsePct(t.sse);
      e.shrink_pct = ShrinkPct(before, e.test_nrmse_after);
      e.excess_reduction = t.excess_red;
      e.delta_bic = t.dbic;
      er[name] = e;
    }
    res.channels.push_back(cs);
  }
  if (!force_ok) {
    ChannelSummary cs;
    cs.channel = "f";
    cs.diagnosed = false;
    cs.status = "not diagnosed";
    res.channels.push_back(cs);
  }

  // Verdict and ranking.
  int pos = 0;
  for (const auto& n : verdict) {
    er[n].order = pos++;
    res.effects.push_back(er[n]);
  }
  std::vector<EffectResult> rest;
  for (const auto& [n, e] : er)
    if (e.order < 0) rest.push_back(e);
  std::sort(rest.begin(), rest.end(), [](const EffectResult& a, const EffectResult& b) { return a.shrink_pct > b.shrink_pct; });
  for (auto& e : rest) res.effects.push_back(e);
  // sensor_noise: the noise floor of each diagnosed channel, never selected.
  for (std::size_t c = 0; c < st.size(); ++c) {
    if (!res.channels[c].diagnosed) continue;
    EffectResult e;
    e.name = "sensor_noise";
    e.channel = res.channels[c].channel;
    e.params["rms"] = res.channels[c].noise_rms;
    e.test_nrmse_after = res.channels[c].gap_test_pct;
    e.train_nrmse_after = res.channels[c].gap_train_pct;
    e.shrink_pct = 0;
    res.effects.push_back(e);
  }
  bool any_structured = false;
  for (const auto& s : st) any_structured |= s->structured;
  if (!verdict.empty()) {
    res.verdict = verdict;
    for (const auto& cs : res.channels)
      if (cs.status == "unexplained")
        res.warnings.push_back(fmt::format("channel {}: a structured residual remains that no candidate explains", cs.channel));
  } else {
    res.verdict = {any_structured ? "unknown" : "none"};
  }

  // --- where (test records, nominal model)
  for (std::size_t c = 0; c < st.size(); ++c) {
    auto& s = *st[c];
    std::vector<LocaliseInput> li;
    std::vector<SmoothedMotion> motions;
    motions.reserve(test.size());
    for (std::size_t r = 0; r < test.size(); ++r) {
      const auto& d = test[r];
      motions.push_back(d.motion.v_mm_s.empty() ? ModelAidedMotion(d.y, st[0]->fin_test[r], dt, std::min(o.smooth_hz, 0.45 / dt))
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
    if (res.channels[c].diagnosed) Localise(std::string(1, s.ch), li, &res.bands, &res.conditions, &res.time);
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
          tr.f_nom = st[1]->nom_test[r];
          tr.f_fin = st[1]->fin_test[r];
        }
        traces->test.push_back(std::move(tr));
      }
    }
  }
  res.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

// ------------------------------------------------------------------------------------------

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
                                   {"samples_pct", num(c.samples_pct)}});
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
  j["options"] = {{"warmup_s", r.options.warmup_s},
                  {"smooth_hz", r.options.smooth_hz},
                  {"none_ratio", r.options.none_ratio},
                  {"min_excess_reduction", r.options.min_excess_reduction},
                  {"min_floor_gain", r.options.min_floor_gain},
                  {"max_test_worsening", r.options.max_test_worsening},
                  {"min_test_shrink_pct", r.options.min_test_shrink_pct},
                  {"detrend", r.options.detrend}};
  return j;
}

std::string Summary(const Result& r) {
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
    for (const auto& c : r.conditions)
      if (c.channel == ch && c.samples_pct > 0 && (!tc || c.share_pct / c.samples_pct > tc->share_pct / tc->samples_pct)) tc = &c;
    if (tc) s += fmt::format("; {} holds {:.1f} % of it in {:.1f} % of the samples", tc->name, tc->share_pct, tc->samples_pct);
    if (top) s += "\n";
  }
  s += "effects (test NRMSE after, shrink):\n";
  for (const auto& e : r.effects) {
    std::string ps;
    for (const auto& [k, v] : e.params) ps += fmt::format(" {}={:.4g}", k, v);
    s += fmt::format("  {} {:<22} [{}]{}: {:.3f} %, shrink {:.1f} % (train: excess -{:.0f} %)\n", e.selected ? "*" : " ", e.name,
                     e.channel, ps, e.test_nrmse_after, e.shrink_pct, 100.0 * e.excess_reduction);
  }
  s += fmt::format("verdict: {}\n", fmt::join(r.verdict, ", "));
  for (const auto& w : r.warnings) s += "warning: " + w + "\n";
  s += fmt::format("runtime: {:.2f} s\n", r.runtime_s);
  return s;
}

}  // namespace rths::diagnosis
