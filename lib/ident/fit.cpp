#include "ident/fit.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/error.h"
#include "ident/lm.h"

namespace rths::ident {

namespace {

using cd = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool Positive(double v) { return std::isfinite(v) && v > 0.0; }

void CheckModel(const PoleModel& m, const char* where) {
  bool ok = Positive(m.K) && (m.p == 0.0 || Positive(m.p)) && m.b.size() == m.c.size() && m.Order() >= 1;
  for (std::size_t j = 0; ok && j < m.b.size(); ++j) ok = Positive(m.b[j]) && Positive(m.c[j]);
  if (!ok) throw Error(where, "model coefficients K, p, b_j, c_j must be finite and > 0");
}

// theta = ln[K, p (odd N), b_1, c_1, b_2, c_2, ...]
Eigen::VectorXd ToTheta(const PoleModel& m) {
  Eigen::VectorXd t(1 + (m.p > 0 ? 1 : 0) + 2 * m.b.size());
  int i = 0;
  t[i++] = std::log(m.K);
  if (m.p > 0) t[i++] = std::log(m.p);
  for (std::size_t j = 0; j < m.b.size(); ++j) t[i++] = std::log(m.b[j]), t[i++] = std::log(m.c[j]);
  return t;
}

PoleModel FromTheta(const Eigen::VectorXd& t, bool odd) {
  PoleModel m;
  int i = 0;
  m.K = std::exp(t[i++]);
  if (odd) m.p = std::exp(t[i++]);
  while (i < t.size()) m.b.push_back(std::exp(t[i++])), m.c.push_back(std::exp(t[i++]));
  return m;
}

// Factors from (approximate) roots: reflect into the left half plane, one real pole for odd N,
// conjugate pairs into quadratics, leftover real roots paired in order of size.
PoleModel FactorsFromRoots(std::vector<cd> roots, double K, double w_scale) {
  const double tiny = 1e-6 * w_scale;
  for (auto& r : roots) {
    double re = -std::abs(r.real());
    if (-re < tiny) re = -tiny;
    r = cd(re, r.imag());
  }
  std::vector<double> reals;
  std::vector<cd> upper;  // one of each complex pair (imag > 0)
  for (const auto& r : roots) {
    if (std::abs(r.imag()) <= 1e-9 * std::abs(r)) {
      reals.push_back(-r.real());
    } else if (r.imag() > 0) {
      upper.push_back(r);
    }
  }
  // An unpaired complex root (numerical asymmetry) is taken as real.
  const std::size_t pairs_expected = (roots.size() - reals.size()) / 2;
  if (upper.size() != pairs_expected) {
    reals.clear();
    upper.clear();
    for (const auto& r : roots) reals.push_back(std::abs(r));
  }
  std::sort(reals.begin(), reals.end());
  PoleModel m;
  m.K = std::max(std::abs(K), tiny);
  if (roots.size() % 2 == 1) {
    // The real pole: the largest real root (Eq. 28's p sits between the pair's modulus and 0).
    m.p = reals.back();
    reals.pop_back();
  }
  for (const auto& r : upper) {
    m.b.push_back(-2.0 * r.real());
    m.c.push_back(std::norm(r));
  }
  for (std::size_t i = 0; i + 1 < reals.size(); i += 2) {
    m.b.push_back(reals[i] + reals[i + 1]);
    m.c.push_back(reals[i] * reals[i + 1]);
  }
  for (std::size_t j = 0; j < m.b.size(); ++j) {
    m.b[j] = std::max(m.b[j], tiny);
    m.c[j] = std::max(m.c[j], tiny * tiny);
  }
  return m;
}

struct Point {
  double f_hz;
  cd h;
  double w;
};

// Step 1: Levy / Sanathanan-Koerner linear fit of K' / D'(s'), s' = j w / w0.
PoleModel LinearStart(const std::vector<Point>& pts, int N, double w0) {
  const int nu = N + 1;  // K', d'_0 .. d'_{N-1}
  std::vector<cd> prev_d(pts.size(), cd(1.0, 0.0));
  Eigen::VectorXd x(nu);
  for (int iter = 0; iter < 8; ++iter) {
    Eigen::MatrixXd A(2 * pts.size(), nu);
    Eigen::VectorXd rhs(2 * pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const cd s(0.0, kTwoPi * pts[k].f_hz / w0);
      const double scale = std::sqrt(pts[k].w) / (std::abs(pts[k].h) * std::abs(prev_d[k]));
      // K' - H sum_i d'_i s^i = H s^N
      cd row[9];
      row[0] = 1.0;
      cd si = 1.0;
      for (int i = 0; i < N; ++i) row[1 + i] = -pts[k].h * si, si *= s;
      const cd r = pts[k].h * si;
      for (int c = 0; c < nu; ++c) {
        A(2 * k, c) = scale * row[c].real();
        A(2 * k + 1, c) = scale * row[c].imag();
      }
      rhs[2 * k] = scale * r.real();
      rhs[2 * k + 1] = scale * r.imag();
    }
    x = A.colPivHouseholderQr().solve(rhs);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const cd s(0.0, kTwoPi * pts[k].f_hz / w0);
      cd d = 1.0;  // Horner, monic
      for (int i = N - 1; i >= 0; --i) d = d * s + x[1 + i];
      prev_d[k] = std::abs(d) > 0 ? d : cd(1.0, 0.0);
    }
  }
  // Roots of the monic D'(s') from its companion matrix, scaled back by w0.
  Eigen::MatrixXd comp = Eigen::MatrixXd::Zero(N, N);
  for (int i = 0; i < N; ++i) comp(0, i) = -x[N - i];  // -d'_{N-1} .. -d'_0
  for (int i = 1; i < N; ++i) comp(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> es(comp, false);
  std::vector<cd> roots;
  for (int i = 0; i < N; ++i) roots.push_back(es.eigenvalues()[i] * w0);
  return FactorsFromRoots(roots, x[0] * std::pow(w0, N), w0);
}

// Residuals r (2 per point: re, im of sqrt(w) (G - H) / |H|) and, if J, their Jacobian in theta.
void Evaluate(const Eigen::VectorXd& theta, bool odd, const std::vector<Point>& pts, double zoh_dt_s,
              Eigen::VectorXd* r, Eigen::MatrixXd* J) {
  const PoleModel m = FromTheta(theta, odd);
  const Eigen::Index np = theta.size();
  r->resize(2 * pts.size());
  if (zoh_dt_s > 0.0) {
    const ZohModel d = Discretise(m, zoh_dt_s);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const cd e = std::sqrt(pts[k].w) * (ZohResponse(d, pts[k].f_hz) - pts[k].h) / std::abs(pts[k].h);
      (*r)[2 * k] = e.real(), (*r)[2 * k + 1] = e.imag();
    }
    if (J) {
      J->resize(2 * pts.size(), np);
      for (Eigen::Index i = 0; i < np; ++i) {
        const double h = 1e-6;
        Eigen::VectorXd tp = theta, tm = theta, rp, rm;
        tp[i] += h;
        tm[i] -= h;
        Evaluate(tp, odd, pts, zoh_dt_s, &rp, nullptr);
        Evaluate(tm, odd, pts, zoh_dt_s, &rm, nullptr);
        J->col(i) = (rp - rm) / (2.0 * h);
      }
    }
    return;
  }
  if (J) J->resize(2 * pts.size(), np);
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const cd s(0.0, kTwoPi * pts[k].f_hz);
    const cd G = m.Response(pts[k].f_hz);
    const double sc = std::sqrt(pts[k].w) / std::abs(pts[k].h);
    const cd e = sc * (G - pts[k].h);
    (*r)[2 * k] = e.real(), (*r)[2 * k + 1] = e.imag();
    if (!J) continue;
    Eigen::Index i = 0;
    auto put = [&](cd dG) {
      (*J)(2 * k, i) = sc * dG.real();
      (*J)(2 * k + 1, i) = sc * dG.imag();
      ++i;
    };
    put(G);
    if (odd) put(-G * m.p / (s + m.p));
    for (std::size_t j = 0; j < m.b.size(); ++j) {
      const cd q = s * s + m.b[j] * s + m.c[j];
      put(-G * m.b[j] * s / q);
      put(-G * m.c[j] / q);
    }
  }
}

}  // namespace

int PoleModel::Order() const { return (p > 0.0 ? 1 : 0) + 2 * static_cast<int>(b.size()); }

std::complex<double> PoleModel::Response(double f_hz) const {
  const cd s(0.0, kTwoPi * f_hz);
  cd d = p > 0.0 ? s + p : cd(1.0, 0.0);
  for (std::size_t j = 0; j < b.size(); ++j) d *= s * s + b[j] * s + c[j];
  return K / d;
}

std::vector<std::complex<double>> PoleModel::Poles() const {
  std::vector<cd> out;
  if (p > 0.0) out.emplace_back(-p, 0.0);
  for (std::size_t j = 0; j < b.size(); ++j) {
    const cd disc = std::sqrt(cd(b[j] * b[j] - 4.0 * c[j], 0.0));
    out.push_back((-b[j] + disc) / 2.0);
    out.push_back((-b[j] - disc) / 2.0);
  }
  return out;
}

std::vector<double> PoleModel::Denominator() const {
  std::vector<double> d{1.0};
  auto mul = [&d](const std::vector<double>& f) {  // f ascending
    std::vector<double> out(d.size() + f.size() - 1, 0.0);
    for (std::size_t i = 0; i < d.size(); ++i)
      for (std::size_t j = 0; j < f.size(); ++j) out[i + j] += d[i] * f[j];
    d = out;
  };
  if (p > 0.0) mul({p, 1.0});
  for (std::size_t j = 0; j < b.size(); ++j) mul({c[j], b[j], 1.0});
  return d;
}

double PoleModel::DcGain() const { return K / Denominator()[0]; }

double PoleModel::DcLagS() const {
  const auto d = Denominator();
  return d.size() > 1 ? d[1] / d[0] : 0.0;
}

models::ServoModel3 PoleModel::ToServoModel3() const {
  if (Order() != 3 || b.size() != 1)
    throw Error("PoleModel", fmt::format("a scenario's servo model has 3 poles (this one has {})", Order()));
  models::ServoModel3 m;
  m.K = K, m.p = p, m.b = b[0], m.c = c[0], m.name = "custom";
  return m;
}

PoleModel PoleModel::FromServoModel3(const models::ServoModel3& s) {
  PoleModel m;
  m.K = s.K, m.p = s.p, m.b = {s.b}, m.c = {s.c};
  return m;
}

ZohModel Discretise(const PoleModel& m, double dt_s) {
  CheckModel(m, "Discretise");
  if (!Positive(dt_s)) throw Error("Discretise", fmt::format("dt_s must be > 0 (got {})", dt_s));
  const int n = m.Order();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd B = Eigen::VectorXd::Zero(n);
  // Cascade: [x1 (odd N)], then per quadratic j: q_j' = sqrt(c) r_j, r_j' = -sqrt(c) q_j - b r_j + v / sqrt(c),
  // v = previous section's output (x1 or q_{j-1}) or u for the first section.
  int prev = -1;  // index of the previous section's output state
  int i = 0;
  if (m.p > 0.0) {
    A(0, 0) = -m.p;
    B[0] = 1.0;
    prev = 0;
    i = 1;
  }
  for (std::size_t j = 0; j < m.b.size(); ++j, i += 2) {
    const double w = std::sqrt(m.c[j]);
    A(i, i + 1) = w;
    A(i + 1, i) = -w;
    A(i + 1, i + 1) = -m.b[j];
    if (prev < 0) {
      B[i + 1] = 1.0 / w;
    } else {
      A(i + 1, prev) = 1.0 / w;
    }
    prev = i;
  }
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + 1, n + 1);
  aug.topLeftCorner(n, n) = A * dt_s;
  aug.topRightCorner(n, 1) = B * dt_s;
  const Eigen::MatrixXd e = aug.exp();
  ZohModel d;
  d.dt_s = dt_s;
  d.Phi = e.topLeftCorner(n, n);
  d.Gamma = e.topRightCorner(n, 1);
  d.C = Eigen::RowVectorXd::Zero(n);
  d.C[prev] = m.K;
  return d;
}

std::complex<double> ZohResponse(const ZohModel& d, double f_hz) {
  const Eigen::Index n = d.Phi.rows();
  const cd z = std::exp(cd(0.0, kTwoPi * f_hz * d.dt_s));
  const Eigen::MatrixXcd M = z * Eigen::MatrixXcd::Identity(n, n) - d.Phi.cast<cd>();
  const Eigen::VectorXcd x = M.partialPivLu().solve(d.Gamma.cast<cd>());
  return (d.C.cast<cd>() * x).value();
}

std::vector<double> SimulateZoh(const ZohModel& d, std::span<const double> u) {
  std::vector<double> y(u.size());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.Phi.rows());
  for (std::size_t k = 0; k < u.size(); ++k) {
    y[k] = d.C.dot(x);
    x = d.Phi * x + d.Gamma * u[k];
  }
  return y;
}

bool FitOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (poles < 1 || poles > 8) return fail(fmt::format("poles = {}: allowed [1, 8]", poles));
  if (!(band_lo_hz >= 0.0) || !std::isfinite(band_lo_hz))
    return fail(fmt::format("band_lo_hz = {}: must be >= 0", band_lo_hz));
  if (!(band_hi_hz > band_lo_hz) || !std::isfinite(band_hi_hz))
    return fail(fmt::format("band_hi_hz = {}: must be > band_lo_hz = {}", band_hi_hz, band_lo_hz));
  if (!(zoh_dt_s >= 0.0) || !std::isfinite(zoh_dt_s))
    return fail(fmt::format("zoh_dt_s = {}: must be >= 0 (0 = continuous model)", zoh_dt_s));
  if (max_iterations < 1 || max_iterations > 100000)
    return fail(fmt::format("max_iterations = {}: allowed [1, 100000]", max_iterations));
  return true;
}

namespace {

/// Step 1's input: the points in the band with coherence > 0, weighted by o.weighting.
std::vector<Point> WeightedPoints(std::span<const double> f_hz, std::span<const std::complex<double>> h,
                                  std::span<const double> coherence, const FitOptions& o) {
  std::vector<Point> pts;
  for (std::size_t k = 0; k < f_hz.size(); ++k) {
    if (!(f_hz[k] >= o.band_lo_hz && f_hz[k] <= o.band_hi_hz) || f_hz[k] <= 0.0) continue;
    if (!(std::abs(h[k]) > 0.0) || !std::isfinite(std::abs(h[k]))) continue;
    const double g2 = std::clamp(coherence[k], 0.0, 1.0);
    if (!(g2 > 0.0)) continue;  // gamma^2 = 0: no linear relation (or left out by the caller)
    double w = 1.0;
    if (o.weighting == Weighting::kCoherence) w = g2;
    if (o.weighting == Weighting::kInverseVariance) w = std::min(g2, 0.999) / (1.0 - std::min(g2, 0.999));
    if (w > 0.0) pts.push_back({f_hz[k], h[k], w});
  }
  return pts;
}

/// Step 2: Levenberg-Marquardt (Marquardt's diagonal scaling) on theta from start, in a box (a
/// projected step): every rate p, b_j, sqrt(c_j) within 1e-3 .. 1e3 times w_hi = 2 pi band_hi (far
/// outside any band one can fit), K within e^(+/-300). Sets out's model, iterations and
/// converged; returns the cost (the weighted sum of squares).
double LevenbergMarquardt(const std::vector<Point>& pts, const PoleModel& start, const FitOptions& o, FitSummary* out) {
  const bool odd = o.poles % 2 == 1;
  const double w_hi = kTwoPi * o.band_hi_hz, lo = std::log(1e-3 * w_hi), hi = std::log(1e3 * w_hi);
  Eigen::VectorXd theta = ToTheta(start), r, rn;
  Eigen::VectorXd lower(theta.size()), upper(theta.size());
  lower[0] = -300.0, upper[0] = 300.0;
  for (Eigen::Index i = 1; i < theta.size(); ++i) {
    const bool is_c = (odd ? i - 2 : i - 1) % 2 == 1 && !(odd && i == 1);
    lower[i] = is_c ? 2.0 * lo : lo;
    upper[i] = is_c ? 2.0 * hi : hi;
  }
  theta = theta.cwiseMax(lower).cwiseMin(upper);
  Eigen::MatrixXd J;
  Evaluate(theta, odd, pts, o.zoh_dt_s, &r, &J);
  struct Cost {
    double cost;
  };
  Cost ev{r.squaredNorm()};
  double lambda = 1e-3;
  // The damped step of lm.h with this fit's damping (PoleFitDamping).
  const LmDamping rule = PoleFitDamping();
  const auto evaluate = [&](const Eigen::VectorXd& trial) {
    Evaluate(trial, odd, pts, o.zoh_dt_s, &rn, nullptr);
    return Cost{rn.squaredNorm()};
  };
  int it = 0;
  for (; it < o.max_iterations; ++it) {
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    const LmStep step = DampedStep(JtJ, g, &theta, &ev, &lambda, evaluate, lower, upper, rule);
    if (!step.accepted) {  // no descent direction left: at a minimum (to rounding)
      out->converged = true;
      break;
    }
    Evaluate(theta, odd, pts, o.zoh_dt_s, &r, &J);
    if (step.solved_norm < 1e-12 || step.old_cost - step.new_cost <= 1e-15 * std::max(ev.cost, 1e-300)) {
      out->converged = true;
      ++it;
      break;
    }
  }
  out->iterations = it;
  out->model = FromTheta(theta, odd);
  return ev.cost;
}

/// The fitted response's errors at the points (of its ZOH discretisation if o.zoh_dt_s > 0).
void ScoreFit(const std::vector<Point>& pts, const FitOptions& o, FitSummary* out) {
  const ZohModel zoh = o.zoh_dt_s > 0.0 ? Discretise(out->model, o.zoh_dt_s) : ZohModel{};
  double se = 0.0;
  for (const auto& pt : pts) {
    const cd G = o.zoh_dt_s > 0.0 ? ZohResponse(zoh, pt.f_hz) : out->model.Response(pt.f_hz);
    se += std::norm(G - pt.h) / std::norm(pt.h);
    out->max_mag_error_pct = std::max(out->max_mag_error_pct, 100.0 * std::abs(std::abs(G) / std::abs(pt.h) - 1.0));
    out->max_phase_error_deg = std::max(out->max_phase_error_deg, std::abs(std::arg(G / pt.h)) * 180.0 / std::numbers::pi);
  }
  out->rms_rel_error = std::sqrt(se / static_cast<double>(pts.size()));
}

}  // namespace

FitSummary FitPoleModel(std::span<const double> f_hz, std::span<const std::complex<double>> h,
                        std::span<const double> coherence, const FitOptions& o) {
  if (f_hz.size() != h.size() || f_hz.size() != coherence.size())
    throw Error("FitPoleModel", fmt::format("f_hz, h and coherence differ in length ({}, {}, {})", f_hz.size(),
                                            h.size(), coherence.size()));
  std::string why;
  if (!o.IsValid(&why)) throw Error("FitPoleModel", why);
  const std::vector<Point> pts = WeightedPoints(f_hz, h, coherence, o);
  const int N = o.poles;
  if (pts.size() < static_cast<std::size_t>(2 * (N + 1)))
    throw Error("FitPoleModel", fmt::format("only {} usable frequency points in the band {}-{} Hz (need at least "
                                            "{} for {} poles)",
                                            pts.size(), o.band_lo_hz, o.band_hi_hz, 2 * (N + 1), N));
  double wsum = 0.0;
  for (const auto& pt : pts) wsum += pt.w;
  FitSummary out;
  out.points = pts.size();
  out.linear_start = LinearStart(pts, N, kTwoPi * o.band_hi_hz);
  const double cost = LevenbergMarquardt(pts, out.linear_start, o, &out);
  out.weighted_rms_rel_error = std::sqrt(cost / wsum);
  ScoreFit(pts, o, &out);
  return out;
}

std::string FitSummary::Report() const {
  std::string s;
  const auto& m = model;
  s += fmt::format("model: G(s) = {:.6g} / (", m.K);
  bool first = true;
  if (m.p > 0) s += fmt::format("(s + {:.6g})", m.p), first = false;
  for (std::size_t j = 0; j < m.b.size(); ++j) {
    s += fmt::format("{}(s^2 + {:.6g} s + {:.6g})", first ? "" : " ", m.b[j], m.c[j]);
    first = false;
  }
  s += ")\n";
  s += "poles [1/s]:";
  for (const auto& pl : m.Poles()) {
    if (pl.imag() == 0.0) {
      s += fmt::format(" {:.6g}", pl.real());
    } else if (pl.imag() > 0.0) {
      const double wn = std::abs(pl);
      s += fmt::format(" {:.6g} +/- {:.6g}j (f_n = {:.4g} Hz, zeta = {:.4g})", pl.real(), pl.imag(),
                       wn / kTwoPi, -pl.real() / wn);
    }
  }
  s += "\n";
  s += fmt::format("DC gain {:.6g} mm/mm, DC lag d1/d0 = {:.4g} ms\n", m.DcGain(), 1e3 * m.DcLagS());
  s += fmt::format("fit over {} points: RMS relative complex error {:.3g} % (weighted {:.3g} %), max magnitude "
                   "error {:.3g} %, max phase error {:.3g} deg; {} Levenberg-Marquardt iterations{}\n",
                   points, 100.0 * rms_rel_error, 100.0 * weighted_rms_rel_error, max_mag_error_pct,
                   max_phase_error_deg, iterations, converged ? "" : " (not converged)");
  return s;
}

}  // namespace rths::ident
