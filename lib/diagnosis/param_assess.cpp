// AssessParameters of stages.h: the selected effects' standard errors and their fits per time
// segment of the training records (docs/diagnosis.md "Drift").
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "diagnosis/candidates.h"
#include "diagnosis/residual_stats.h"
#include "diagnosis/search.h"
#include "diagnosis/stages.h"
#include "diagnosis/tuning.h"

namespace rths::diagnosis::stages {

namespace {

/// The samples of segment [a, b) (fractions of a record's summed span [first, n)).
std::pair<std::size_t, std::size_t> SegmentOf(const Data& d, double a, double b) {
  const auto span = static_cast<double>(d.size() - d.first);
  const auto lo = d.first + static_cast<std::size_t>(std::floor(a * span));
  const auto hi = b >= 1.0 ? d.size() : d.first + static_cast<std::size_t>(std::floor(b * span));
  return {lo, hi};
}

/// SSE of a prediction over segment [a, b) of every record; *count the samples.
double SegmentSse(const Channel& ch, const std::vector<std::vector<double>>& pred, double a, double b,
                  std::size_t* count) {
  double s = 0.0;
  std::size_t n = 0;
  for (std::size_t r = 0; r < ch.recs().size(); ++r) {
    const auto meas = ch.Meas(r);
    const auto [lo, hi] = SegmentOf(ch.recs()[r], a, b);
    for (std::size_t k = lo; k < hi; ++k) s += (meas[k] - pred[r][k]) * (meas[k] - pred[r][k]);
    n += hi - lo;
  }
  if (count) *count = n;
  return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
}

/// Grid points of a segment's bracket before golden section.
constexpr int kSegmentGrid = 5;

/// One parameter's fit and standard error on a segment [a, b) of the training records.
struct SegmentFit {
  double value = 0, se = std::numeric_limits<double>::infinity();
};

class ParamProbe {
 public:
  ParamProbe(const ChannelState& s, const std::vector<CandidateSpec>& specs, const std::string& name, std::size_t j,
             double tau)
      : s_(s), specs_(specs), name_(name), j_(j), range_(SpecOf(specs, name).params[j]), tau_(tau) {}

  /// The SSE over [a, b) with the parameter at x (the rest of the set held, the linear terms too).
  double Sse(double x, double a, double b, std::size_t* n = nullptr) const {
    Params q = s_.sel;
    q[name_][j_] = x;
    return SegmentSse(s_.train, s_.train.Predict(ToSet(specs_, q), nullptr, true), a, b, n);
  }

  /// The standard error at x from the curvature of the SSE over [a, b): se^2 = 2 (SSE / n) tau / SSE''.
  double Se(double x, double a, double b) const {
    std::size_t n = 0;
    const double s0 = Sse(x, a, b, &n);
    const double h = range_.log ? std::abs(x) * tuning::kCurvatureStep : tuning::kCurvatureStep * (range_.hi - range_.lo);
    if (!(h > 0.0) || n == 0) return std::numeric_limits<double>::infinity();
    const double sp = Sse(x + h, a, b), sm = Sse(x - h, a, b);
    const double curv = (sp - 2.0 * s0 + sm) / (h * h);
    if (!(curv > 0.0) || !std::isfinite(curv)) return std::numeric_limits<double>::infinity();
    return std::sqrt(2.0 * (s0 / static_cast<double>(n)) * tau_ / curv);
  }

  /// The fit over [a, b), searched around v (tuning::kSegmentBracketFactor / Fraction).
  SegmentFit Fit(double v, double a, double b) const {
    const ParamSpec br =
        BracketAround(range_, v, tuning::kSegmentBracketFactor, tuning::kSegmentBracketFraction, kSegmentGrid);
    double best = 0.0;
    SegmentFit f;
    f.value = Minimise1D([&](double x) { return Sse(x, a, b); }, br, tuning::kSegmentGoldenIters, &best, {v});
    f.se = Se(f.value, a, b);
    return f;
  }

  const ParamSpec& range() const { return range_; }

 private:
  const ChannelState& s_;
  const std::vector<CandidateSpec>& specs_;
  std::string name_;
  std::size_t j_;
  ParamSpec range_;
  double tau_;
};

/// true if the training records' excitation is alike in every segment (tuning::kSegmentExcitationRatio):
/// the rms of the command, its rms rate over its rms (an effective frequency) and the rms current
/// differ by at most that ratio between any two segments. A chirp or a stepped sine sweeps its
/// frequency over the record: a segment's fit then also answers the excitation, and a form that is
/// not quite the rig's gives each band its own value, which is no drift.
bool SegmentsAlike(const Channel& ch, int K) {
  std::vector<double> uu(K, 0.0), vv(K, 0.0), ii(K, 0.0), nn(K, 0.0);
  for (const auto& d : ch.recs())
    for (int q = 0; q < K; ++q) {
      const auto [lo, hi] = SegmentOf(d, static_cast<double>(q) / K, static_cast<double>(q + 1) / K);
      for (std::size_t k = std::max<std::size_t>(lo, 1); k < hi; ++k) {
        const double du = (d.u[k] - d.u[k - 1]) / d.dt;
        uu[q] += d.u[k] * d.u[k], vv[q] += du * du, ii[q] += d.i[k] * d.i[k], nn[q] += 1.0;
      }
    }
  auto spread = [&](auto value) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (int q = 0; q < K; ++q) lo = std::min(lo, value(q)), hi = std::max(hi, value(q));
    return hi <= tuning::kSegmentExcitationRatio * lo || hi == 0.0;
  };
  for (int q = 0; q < K; ++q)
    if (!(nn[q] > 0.0)) return false;
  const bool u_alike = spread([&](int q) { return std::sqrt(uu[q] / nn[q]); });
  const bool f_alike = spread([&](int q) { return uu[q] > 0.0 ? std::sqrt(vv[q] / uu[q]) : 0.0; });
  // The current: alike if its rms levels are within the ratio, or all small against the largest.
  double imax = 0.0;
  for (int q = 0; q < K; ++q) imax = std::max(imax, std::sqrt(ii[q] / nn[q]));
  const bool i_alike = imax == 0.0 || spread([&](int q) { return std::max(std::sqrt(ii[q] / nn[q]), 0.1 * imax); });
  return u_alike && f_alike && i_alike;
}

/// The linear terms of the force (damper_scale's scale, load_cell_inertia's mass) do not depend on
/// the excitation when the model's form is right: their segments are compared whatever it is.
bool ExcitationFree(const std::string& name) { return name == "damper_scale" || name == "load_cell_inertia"; }

/// The segment fits' chi^2 about their se-weighted mean.
double Chi2(const std::vector<double>& v, const std::vector<double>& se) {
  double sw = 0.0, swv = 0.0;
  for (std::size_t j = 0; j < v.size(); ++j)
    if (std::isfinite(se[j]) && se[j] > 0.0) sw += 1.0 / (se[j] * se[j]), swv += v[j] / (se[j] * se[j]);
  if (!(sw > 0.0)) return 0.0;
  const double mean = swv / sw;
  double c = 0.0;
  for (std::size_t j = 0; j < v.size(); ++j)
    if (std::isfinite(se[j]) && se[j] > 0.0) c += (v[j] - mean) * (v[j] - mean) / (se[j] * se[j]);
  return c;
}

}  // namespace

void AssessParameters(const ChannelState& s, const std::vector<CandidateSpec>& specs, EffectResults* er,
                      std::vector<std::string>* warnings) {
  if (s.order.empty() || (!s.retained && s.unconfirmed.empty())) return;
  const double tau = IntegratedCorrelationTime(s.train, s.pred_train);
  const int K = tuning::kDriftSegments;
  const bool alike = SegmentsAlike(s.train, K);
  std::vector<std::string> unjudged;
  for (const auto& name : s.order) {
    if (name == "supply_ripple") continue;  // fitted per record (its phases): no constant to follow
    const CandidateSpec& spec = SpecOf(specs, name);
    EffectResult& e = (*er)[name];
    std::vector<std::string> drifting;
    for (std::size_t j = 0; j < spec.params.size(); ++j) {
      if (spec.params[j].grid < 0) continue;  // a switch: no uncertainty, no drift
      const ParamProbe probe(s, specs, name, j, tau);
      const double v = s.sel.at(name)[j];
      const double se = probe.Se(v, 0.0, 1.0);
      e.params_se[spec.params[j].key] = se;
      if (name == "load_cell_inertia" && !(v > 2.0 * se))
        warnings->push_back(fmt::format("channel {}: load_cell_inertia's mass {:.3g} kg is within two standard errors "
                                        "({:.2g} kg) of 0: the records' acceleration is too small to tell it from noise",
                                        s.summary.channel, v, se));
      EffectResult::Drift dr;
      dr.key = spec.params[j].key;
      for (int q = 0; q < K; ++q) {
        const SegmentFit f = probe.Fit(v, static_cast<double>(q) / K, static_cast<double>(q + 1) / K);
        dr.values.push_back(f.value);
        dr.se.push_back(f.se);
      }
      dr.chi2 = Chi2(dr.values, dr.se);
      const double first = dr.values.front(), last = dr.values.back();
      const double size = std::max(std::abs(v), 0.01 * (probe.range().hi - probe.range().lo));
      const double se_diff = std::hypot(dr.se.front(), dr.se.back());
      const bool drifts = dr.chi2 > tuning::kDriftChi2 && std::abs(last - first) > tuning::kDriftMinRelative * size &&
                          std::abs(last - first) > tuning::kDriftMinSigmas * se_diff;
      if (drifts && (alike || ExcitationFree(name))) drifting.push_back(fmt::format("{} {:.3g} -> {:.3g}", dr.key, first, last));
      else if (drifts) unjudged.push_back(fmt::format("{}.{} {:.3g} -> {:.3g}", name, dr.key, first, last));
      e.segments.push_back(std::move(dr));
    }
    if (!drifting.empty()) {
      e.drift = fmt::format("drifting over the record: {}", fmt::join(drifting, ", "));
      warnings->push_back(fmt::format(
          "channel {}: {} is not constant over the training records ({}, fitted per {} of each record): a parameter "
          "that changes during the test is not this library effect's constant; the fit is its average",
          s.summary.channel, name, e.drift.substr(std::string("drifting over the record: ").size()),
          K == 4 ? "quarter" : fmt::format("1/{}", K)));
    }
  }
  if (!unjudged.empty())
    warnings->push_back(fmt::format(
        "channel {}: {} varies over the training records, but so does their excitation (its level, frequency or "
        "current differs by more than {:g} x between segments: a sweep): a drift cannot be told from the effect's "
        "form answering each band; not called a drift (a test that repeats one excitation can tell)",
        s.summary.channel, fmt::join(unjudged, ", "), tuning::kSegmentExcitationRatio));
}

}  // namespace rths::diagnosis::stages
