#include "diagnosis/localise.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>

#include "signal/spectral.h"

namespace rths::diagnosis {

namespace {

double Rms(std::span<const double> x) {
  if (x.empty()) return 0.0;
  double s = 0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

}  // namespace

ConditionMasks MakeConditionMasks(const LocaliseInput& r) {
  const std::size_t n = r.v.size();
  ConditionMasks cm;
  const double dt = r.dt_s;
  // velocity_reversal
  {
    std::vector<char> m(n, 0);
    const auto w = static_cast<std::ptrdiff_t>(std::lround(0.010 / dt));
    for (std::size_t k = 1; k < n; ++k) {
      if ((r.v[k - 1] > 0) != (r.v[k] > 0)) {
        const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(k) - w);
        const std::ptrdiff_t b = std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(n) - 1, static_cast<std::ptrdiff_t>(k) + w);
        for (std::ptrdiff_t j = a; j <= b; ++j) m[static_cast<std::size_t>(j)] = 1;
      }
    }
    cm.names.push_back("velocity_reversal");
    cm.masks.push_back(std::move(m));
  }
  // high_velocity
  {
    const double rv = Rms(r.v.subspan(std::min(r.first, n)));
    std::vector<char> m(n, 0);
    for (std::size_t k = 0; k < n; ++k) m[k] = std::abs(r.v[k]) > 1.5 * rv;
    cm.names.push_back("high_velocity");
    cm.masks.push_back(std::move(m));
  }
  // high_force
  if (r.f_meas.size() == n) {
    const double rf = Rms(r.f_meas.subspan(std::min(r.first, n)));
    if (rf > 0) {
      std::vector<char> m(n, 0);
      for (std::size_t k = 0; k < n; ++k) m[k] = std::abs(r.f_meas[k]) > 1.5 * rf;
      cm.names.push_back("high_force");
      cm.masks.push_back(std::move(m));
    }
  }
  // current_switching
  if (r.i.size() == n) {
    std::vector<char> m(n, 0);
    const auto w = static_cast<std::size_t>(std::lround(0.100 / dt));
    for (std::size_t k = 1; k < n; ++k) {
      if (std::abs(r.i[k] - r.i[k - 1]) > 0.05) {
        for (std::size_t j = k; j < std::min(n, k + w + 1); ++j) m[j] = 1;
      }
    }
    cm.names.push_back("current_switching");
    cm.masks.push_back(std::move(m));
  }
  return cm;
}

namespace {

/// The bands' edges [Hz]: 0, 1, 2, 5, 10, ... below f_Nyquist, then f_Nyquist.
std::vector<double> BandEdges(double dt) {
  const double nyq = 0.5 / dt;
  std::vector<double> edges = {0, 1, 2, 5, 10, 20, 50, 100, 200, 500};
  while (!edges.empty() && edges.back() >= nyq) edges.pop_back();
  edges.push_back(nyq);
  return edges;
}

/// Per band: residual and signal energy, and (y only) the measured-power-weighted sums of the
/// coherence, the gain ratio and the phase difference of H_meas / H_model.
struct BandSums {
  explicit BandSums(std::size_t nb) : e_res(nb, 0), e_sig(nb, 0), coh(nb, 0), gain(nb, 0), phase(nb, 0), wsum(nb, 0) {}
  std::vector<double> e_res, e_sig, coh, gain, phase, wsum;
};

/// Adds one record's Welch spectra (segments of 2 s, at least 64 samples, at most 1/8 of the
/// record) to the sums; dt [s] is the first record's (one dt per diagnosis).
void AddRecordBands(const std::string& channel, const LocaliseInput& r, double dt, const std::vector<double>& edges,
                    BandSums* s) {
  const std::size_t nb = edges.size() - 1;
  const std::size_t n = r.meas.size();
  if (n <= r.first + 64) return;
  std::vector<double> res(n - r.first), meas(r.meas.begin() + static_cast<std::ptrdiff_t>(r.first), r.meas.end());
  for (std::size_t k = r.first; k < n; ++k) res[k - r.first] = r.meas[k] - r.pred[k];
  const std::size_t L = std::max<std::size_t>(64, std::min<std::size_t>(static_cast<std::size_t>(std::lround(2.0 / dt)), res.size() / 8));
  const auto pr = signal::WelchPsd(res, dt, L);
  const auto pm = signal::WelchPsd(meas, dt, L);
  const double df = 1.0 / (dt * static_cast<double>(L));
  signal::FrequencyResponseEstimate hm, hp;
  const bool frf = channel == "y" && r.u.size() == n;
  if (frf) {
    std::vector<double> u(r.u.begin() + static_cast<std::ptrdiff_t>(r.first), r.u.end());
    std::vector<double> pred(r.pred.begin() + static_cast<std::ptrdiff_t>(r.first), r.pred.end());
    hm = signal::H1Estimate(u, meas, dt, L);
    hp = signal::H1Estimate(u, pred, dt, L);
  }
  for (std::size_t j = 0; j < pr.size(); ++j) {
    const double f = static_cast<double>(j) * df;
    std::size_t b = 0;
    while (b + 1 < nb && f >= edges[b + 1]) ++b;
    s->e_res[b] += pr[j] * df;
    s->e_sig[b] += pm[j] * df;
    if (frf && j > 0 && std::abs(hp.h[j]) > 0) {
      const std::complex<double> ratio = hm.h[j] / hp.h[j];
      const double w = pm[j];  // weight by the measured power
      s->coh[b] += w * hm.coherence[j];
      s->gain[b] += w * std::abs(ratio);
      s->phase[b] += w * std::arg(ratio) * 180.0 / M_PI;
      s->wsum[b] += w;
    }
  }
}

void LocaliseBands(const std::string& channel, const std::vector<LocaliseInput>& recs, std::vector<Band>* bands) {
  const double dt = recs[0].dt_s;
  const std::vector<double> edges = BandEdges(dt);
  const std::size_t nb = edges.size() - 1;
  BandSums s(nb);
  for (const auto& r : recs) AddRecordBands(channel, r, dt, edges, &s);
  const double tot_r = std::accumulate(s.e_res.begin(), s.e_res.end(), 0.0);
  const double tot_s = std::accumulate(s.e_sig.begin(), s.e_sig.end(), 0.0);
  for (std::size_t b = 0; b < nb; ++b) {
    Band bd;
    bd.channel = channel;
    bd.lo_hz = edges[b];
    bd.hi_hz = edges[b + 1];
    bd.share_pct = tot_r > 0 ? 100.0 * s.e_res[b] / tot_r : 0.0;
    bd.signal_share_pct = tot_s > 0 ? 100.0 * s.e_sig[b] / tot_s : 0.0;
    bd.rel_residual_pct = s.e_sig[b] > 0 ? 100.0 * std::sqrt(s.e_res[b] / s.e_sig[b]) : 0.0;
    if (s.wsum[b] > 0) {
      bd.coherence = s.coh[b] / s.wsum[b];
      bd.gain_ratio = s.gain[b] / s.wsum[b];
      bd.phase_diff_deg = s.phase[b] / s.wsum[b];
    }
    bands->push_back(bd);
  }
}

/// The conditions' shares; returns the residual energy of all records (k >= first).
double LocaliseConditions(const std::string& channel, const std::vector<LocaliseInput>& recs,
                          std::vector<Condition>* conditions) {
  std::map<std::string, std::pair<double, double>> acc;  // name -> (residual energy, samples)
  std::vector<std::string> order;
  double tot_e = 0, tot_n = 0;
  for (const auto& r : recs) {
    const auto cm = MakeConditionMasks(r);
    const std::size_t n = r.meas.size();
    for (std::size_t k = r.first; k < n; ++k) {
      const double e = r.meas[k] - r.pred[k];
      tot_e += e * e;
      tot_n += 1;
    }
    for (std::size_t c = 0; c < cm.names.size(); ++c) {
      if (!acc.count(cm.names[c])) order.push_back(cm.names[c]);
      auto& a = acc[cm.names[c]];
      for (std::size_t k = r.first; k < n; ++k) {
        if (!cm.masks[c][k]) continue;
        const double e = r.meas[k] - r.pred[k];
        a.first += e * e;
        a.second += 1;
      }
    }
  }
  for (const auto& name : order) {
    Condition c;
    c.channel = channel;
    c.name = name;
    c.share_pct = tot_e > 0 ? 100.0 * acc[name].first / tot_e : 0.0;
    c.samples_pct = tot_n > 0 ? 100.0 * acc[name].second / tot_n : 0.0;
    conditions->push_back(c);
  }
  return tot_e;
}

/// The five windows (1 s, or a tenth of a record shorter than 10 s) holding the largest shares of tot_e.
void LocaliseTime(const std::string& channel, const std::vector<LocaliseInput>& recs, double tot_e,
                  std::vector<TimeWindow>* time) {
  std::vector<TimeWindow> wins;
  for (const auto& r : recs) {
    const std::size_t n = r.meas.size();
    const double dur = static_cast<double>(n) * r.dt_s;
    const double wlen = dur >= 10.0 ? 1.0 : dur / 10.0;
    const auto wn = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(wlen / r.dt_s)));
    for (std::size_t a = 0; a < n; a += wn) {
      const std::size_t b = std::min(n, a + wn);
      double e2 = 0;
      for (std::size_t k = std::max(a, r.first); k < b; ++k) {
        const double e = r.meas[k] - r.pred[k];
        e2 += e * e;
      }
      TimeWindow w;
      w.channel = channel;
      w.record = r.source;
      w.t0_s = static_cast<double>(a) * r.dt_s;
      w.t1_s = static_cast<double>(b) * r.dt_s;
      w.share_pct = tot_e > 0 ? 100.0 * e2 / tot_e : 0.0;
      wins.push_back(w);
    }
  }
  std::sort(wins.begin(), wins.end(), [](const TimeWindow& a, const TimeWindow& b) { return a.share_pct > b.share_pct; });
  if (wins.size() > 5) wins.resize(5);
  for (auto& w : wins) time->push_back(w);
}

}  // namespace

void Localise(const std::string& channel, const std::vector<LocaliseInput>& recs, std::vector<Band>* bands,
              std::vector<Condition>* conditions, std::vector<TimeWindow>* time) {
  if (recs.empty()) return;
  LocaliseBands(channel, recs, bands);
  const double tot_e = LocaliseConditions(channel, recs, conditions);
  LocaliseTime(channel, recs, tot_e, time);
}

}  // namespace rths::diagnosis
