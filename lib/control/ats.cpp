#include "control/ats.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::control {

namespace {

constexpr int kMaxN = kMaxAdaptiveFilterOrder;
/// A scaled normal matrix with a reciprocal condition estimate below this is taken as singular.
constexpr double kMinRcond = 1e-13;
/// Longest accepted window [s] (the ring holds round(window_s / dt) samples).
constexpr double kMaxWindowS = 100.0;
/// Most samples in the window (the ring's size).
constexpr long kMaxWindowSamples = 1L << 22;

std::string Triple(const std::array<double, 3>& v) { return fmt::format("[{}, {}, {}]", v[0], v[1], v[2]); }

void CheckAtsBounds(const AtsConfig& cfg) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(cfg.upper[i])) {
      throw Error("controller.ats.upper", fmt::format("{}: allowed finite numbers", Triple(cfg.upper)));
    }
    if (!std::isfinite(cfg.lower[i]) || !(cfg.lower[i] <= cfg.upper[i])) {
      throw Error("controller.ats.lower",
                  fmt::format("{} (upper {}): allowed finite with lower[i] <= upper[i] (a{} breaks it)",
                              Triple(cfg.lower), Triple(cfg.upper), i));
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!(cfg.initial[i] >= cfg.lower[i] && cfg.initial[i] <= cfg.upper[i])) {
      throw Error("controller.ats.initial",
                  fmt::format("{}: a{} = {} is outside its bounds; allowed [lower, upper] = [{}, {}]",
                              Triple(cfg.initial), i, cfg.initial[i], cfg.lower[i], cfg.upper[i]));
    }
    if (!(cfg.max_rate_per_s[i] > 0.0) || !std::isfinite(cfg.max_rate_per_s[i])) {
      throw Error("controller.ats.max_rate_per_s",
                  fmt::format("{}: allowed finite and > 0 [1/s, s/s, s^2/s]", Triple(cfg.max_rate_per_s)));
    }
  }
}

void CheckAtsSignals(const AtsConfig& cfg, double dt_s) {
  if (cfg.skip < 1) throw Error("controller.ats.skip", fmt::format("{}: allowed >= 1 (samples)", cfg.skip));
  if (!(cfg.window_s > 0.0 && cfg.window_s <= kMaxWindowS)) {
    throw Error("controller.ats.window_s", fmt::format("{} s: allowed (0, {}] s", cfg.window_s, kMaxWindowS));
  }
  const long n = std::lround(cfg.window_s / dt_s);
  if (n > kMaxWindowSamples) {
    throw Error("controller.ats.window_s", fmt::format("{} s is {} samples of {} s: allowed at most {} samples",
                                                       cfg.window_s, n, dt_s, kMaxWindowSamples));
  }
  const long points = (n + cfg.skip - 1) / cfg.skip;
  if (points < 3) {
    throw Error("controller.ats.window_s",
                fmt::format("{} s is {} samples of {} s, every {}-th (controller.ats.skip): {} regression points; "
                            "allowed at least 3 (window_s >= {} s)",
                            cfg.window_s, n, dt_s, cfg.skip, points, (2 * cfg.skip + 0.5) * dt_s));
  }
  if (cfg.filter_order < 1 || cfg.filter_order > kMaxN) {
    throw Error("controller.ats.filter_order", fmt::format("{}: allowed [1, {}]", cfg.filter_order, kMaxN));
  }
  if (!(cfg.filter_hz > 0.0 && cfg.filter_hz < 0.5 / dt_s)) {
    throw Error("controller.ats.filter_hz",
                fmt::format("{} Hz: allowed (0, {}) Hz (below the Nyquist frequency 0.5/run.dt_s)", cfg.filter_hz,
                            0.5 / dt_s));
  }
  if (!(cfg.threshold_mm >= 0.0) || !std::isfinite(cfg.threshold_mm)) {
    throw Error("controller.ats.threshold_mm", fmt::format("{} mm: allowed finite and >= 0", cfg.threshold_mm));
  }
}

/// The least-squares estimate over the window (samples k-N, k-N+skip, ... < k, oldest at
/// s.head), from the normal equations scaled to unit diagonal (Jacobi: the columns are in mm,
/// mm/s and mm/s^2). False if a column is zero, the system is numerically singular or the
/// result is not finite.
bool SolveWindow(const AtsDesign& d, const AtsState& s, std::array<double, 3>* a) {
  Eigen::Matrix3d x = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  const int n = d.window_samples;
  int slot = s.head;
  for (int j = 0; j < d.points; ++j) {
    const AtsSample& p = s.window[slot];
    const Eigen::Vector3d v(p.yf_mm, p.d1_mm_s, p.d2_mm_s2);
    x.noalias() += v * v.transpose();
    y += p.uf_mm * v;
    slot += d.config.skip;
    if (slot >= n) slot -= n;
  }
  const Eigen::Vector3d scale = x.diagonal().cwiseSqrt();
  if (!(scale.minCoeff() > 0.0) || !scale.allFinite()) return false;
  const Eigen::Vector3d inv = scale.cwiseInverse();
  const Eigen::Matrix3d xs = inv.asDiagonal() * x * inv.asDiagonal();
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(xs);
  if (!(lu.rcond() > kMinRcond)) return false;
  const Eigen::Vector3d b = lu.solve(inv.cwiseProduct(y)).cwiseProduct(inv);
  if (!b.allFinite()) return false;
  *a = {b(0), b(1), b(2)};
  return true;
}

}  // namespace

std::complex<double> ZohButterworth::Response(double f_hz) const {
  const int n = order;
  const std::complex<double> z = std::polar(1.0, 2.0 * std::numbers::pi * f_hz * dt_s);
  Eigen::MatrixXcd m = -Eigen::MatrixXcd::Identity(n, n) * z;
  Eigen::VectorXcd g(n);
  Eigen::RowVectorXcd c_row(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) m(i, j) += phi[i * kMaxN + j];
    g(i) = gamma[i];
    c_row(i) = c[i];
  }
  // C (zI - Phi)^-1 Gamma = -C (Phi - zI)^-1 Gamma.
  return -(c_row * m.partialPivLu().solve(g)).value();
}

ZohButterworth MakeZohButterworth(int order, double cutoff_hz, double dt_s) {
  const int n = order;
  const double wc = 2.0 * std::numbers::pi * cutoff_hz;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n), b = Eigen::MatrixXd::Zero(n, 1);
  int in = -1;  // the state feeding the next section; -1: the filter's input
  const auto feed = [&](int row) {
    if (in < 0) {
      b(row, 0) = wc;
    } else {
      a(row, in) = wc;
    }
  };
  int i = 0;
  if (n % 2 == 1) {  // the real pole s + w_c
    a(0, 0) = -wc;
    feed(0);
    in = 0;
    i = 1;
  }
  for (int k = 0; k < n / 2; ++k, i += 2) {  // s^2 + 2 sin(theta_k) w_c s + w_c^2
    const double zeta = std::sin((2 * k + 1) * std::numbers::pi / (2.0 * n));
    a(i, i + 1) = wc;
    a(i + 1, i) = -wc;
    a(i + 1, i + 1) = -2.0 * zeta * wc;
    feed(i + 1);
    in = i;
  }
  Eigen::MatrixXd phi, gamma;
  ZohDiscretise(a, b, dt_s, &phi, &gamma);
  ZohButterworth f;
  f.order = n;
  f.cutoff_hz = cutoff_hz;
  f.dt_s = dt_s;
  for (int r = 0; r < n; ++r) {
    for (int col = 0; col < n; ++col) f.phi[r * kMaxN + col] = phi(r, col);
    f.gamma[r] = gamma(r, 0);
  }
  f.c[in] = 1.0;
  return f;
}

double ZohFilterOutput(const ZohButterworth& f, const ZohFilterState& s) {
  double w = 0.0;
  for (int i = 0; i < f.order; ++i) w += f.c[i] * s.x[i];
  return w;
}

void ZohFilterUpdate(const ZohButterworth& f, ZohFilterState* s, double v_k) {
  std::array<double, kMaxN> next{};
  for (int r = 0; r < f.order; ++r) {
    double v = f.gamma[r] * v_k;
    for (int col = 0; col < f.order; ++col) v += f.phi[r * kMaxN + col] * s->x[col];
    next[r] = v;
  }
  s->x = next;
}

AtsDesign MakeAtsDesign(const AtsConfig& cfg, double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  CheckAtsBounds(cfg);
  CheckAtsSignals(cfg, dt_s);
  AtsDesign d;
  d.config = cfg;
  d.dt_s = dt_s;
  d.window_samples = static_cast<int>(std::lround(cfg.window_s / dt_s));
  d.points = (d.window_samples + cfg.skip - 1) / cfg.skip;
  for (int i = 0; i < 3; ++i) d.max_step[i] = cfg.max_rate_per_s[i] * dt_s;
  d.filter = MakeZohButterworth(cfg.filter_order, cfg.filter_hz, dt_s);
  return d;
}

AtsState AtsAtRest(const AtsDesign& d) {
  AtsState s;
  s.window.assign(static_cast<std::size_t>(d.window_samples), AtsSample{});
  s.a = d.config.initial;
  return s;
}

Command AtsCommand(const AtsDesign& d, AtsState* s, const Derivatives& target) {
  const AtsConfig& cfg = d.config;
  const double dt = d.dt_s;
  // The filtered signals at k (inputs up to k-1) and the Discrete Derivatives (zero before start).
  AtsSample now;
  now.yf_mm = ZohFilterOutput(d.filter, s->filter_y);
  now.uf_mm = ZohFilterOutput(d.filter, s->filter_u);
  now.d1_mm_s = (now.yf_mm - s->yf_mm) / dt;
  now.d2_mm_s2 = (now.d1_mm_s - s->d1_mm_s) / dt;
  s->yf_mm = now.yf_mm;
  s->d1_mm_s = now.d1_mm_s;
  if (!s->triggered && std::abs(now.yf_mm) > cfg.threshold_mm) s->triggered = true;
  if (s->triggered) {
    std::array<double, 3> a = cfg.initial;
    s->fallback = !SolveWindow(d, *s, &a);
    if (s->fallback) a = cfg.initial;
    for (int i = 0; i < 3; ++i) {
      a[i] = std::clamp(a[i], s->a[i] - d.max_step[i], s->a[i] + d.max_step[i]);  // rate limit
      a[i] = std::clamp(a[i], cfg.lower[i], cfg.upper[i]);                         // bounds
    }
    s->a = a;
  }
  // The window moves on: sample k replaces k-N (the oldest).
  s->window[s->head] = now;
  if (++s->head == d.window_samples) s->head = 0;

  double xd = target.rd, xdd = target.rdd;
  if (cfg.derivatives == TargetDerivatives::kDifference) {
    xd = (target.r - s->r1_mm) / dt;
    xdd = (target.r - 2.0 * s->r1_mm + s->r2_mm) / (dt * dt);
  }
  s->r2_mm = s->r1_mm;
  s->r1_mm = target.r;
  const double u = s->a[0] * target.r + s->a[1] * xd + s->a[2] * xdd;
  s->u_mm = u;
  Command c;
  c.u_mm = c.u_ff_mm = u;
  c.u_fb_mm = 0.0;
  c.n_adapt = 3;
  c.adapt = {s->a[0], s->a[1], s->a[2], 0.0};
  return c;
}

void AtsUpdate(const AtsDesign& d, AtsState* s, double y_mm) {
  ZohFilterUpdate(d.filter, &s->filter_y, y_mm);
  ZohFilterUpdate(d.filter, &s->filter_u, s->u_mm);
}

DiscreteSs AdaptiveFir(const std::array<double, 4>& a, TargetDerivatives derivatives, double dt_s) {
  if (derivatives == TargetDerivatives::kIntegrator) {
    return FeedforwardFir(FeedforwardCoefficients{a[0], a[1], a[2], a[3]}, false, dt_s);
  }
  // sum_i a_i D_i with D1 = [1 -1]/dt, D2 = [1 -2 1]/dt^2, D3 = [1 -3 3 -1]/dt^3 on r_k .. r_{k-3}.
  const double c1 = a[1] / dt_s, c2 = a[2] / (dt_s * dt_s), c3 = a[3] / (dt_s * dt_s * dt_s);
  const Eigen::Vector4d h(a[0] + c1 + c2 + c3, -c1 - 2.0 * c2 - 3.0 * c3, c2 + 3.0 * c3, -c3);
  return Fir(h, dt_s);
}

ControllerLti AtsController::Linearize(double) const {
  const auto& a = design_.config.initial;
  return {AdaptiveFir({a[0], a[1], a[2], 0.0}, design_.config.derivatives, design_.dt_s), false, {}};
}

}  // namespace rths::control
