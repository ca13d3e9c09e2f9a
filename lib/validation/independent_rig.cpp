#include "validation/independent_rig.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "models/mr_damper.h"     // the parameter struct only (Table 3)
#include "models/servo_linear.h"  // the parameter struct only (Eq. 30, "avg")
#include "signal/random.h"        // seeded Gaussian deviates

namespace rths::validation {

std::string_view Name(CommandFamily f) {
  switch (f) {
    case CommandFamily::kBandNoise: return "band_noise";
    case CommandFamily::kChirp: return "chirp";
    case CommandFamily::kMultisine: return "multisine";
    case CommandFamily::kEarthquake: return "earthquake";
  }
  return "?";
}

std::string_view Name(CurrentPattern p) {
  switch (p) {
    case CurrentPattern::kPulsed: return "pulsed";
    case CurrentPattern::kConstant: return "constant";
    case CurrentPattern::kStaircase: return "staircase";
    case CurrentPattern::kTelegraph: return "telegraph";
  }
  return "?";
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// ------------------------------------------------------------------------------------------
// Filters (RBJ biquads, i.e. bilinear with prewarping at the corner), written here.

struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
  double z1 = 0, z2 = 0;
  double Step(double x) {
    const double y = b0 * x + z1;
    z1 = b1 * x - a1 * y + z2;
    z2 = b2 * x - a2 * y;
    return y;
  }
};

/// One second-order section of quality q at fc [Hz], sampling rate fs [Hz]; high = high-pass.
Biquad Section(double fc, double fs, double q, bool high) {
  const double w0 = 2.0 * kPi * fc / fs, cw = std::cos(w0), al = std::sin(w0) / (2.0 * q), a0 = 1.0 + al;
  Biquad s;
  if (high) {
    s.b0 = 0.5 * (1.0 + cw) / a0, s.b1 = -(1.0 + cw) / a0, s.b2 = s.b0;
  } else {
    s.b0 = 0.5 * (1.0 - cw) / a0, s.b1 = (1.0 - cw) / a0, s.b2 = s.b0;
  }
  s.a1 = -2.0 * cw / a0, s.a2 = (1.0 - al) / a0;
  return s;
}

/// Butterworth of even order: sections of q_k = 1 / (2 sin(pi (2k + 1) / (2 order))).
std::vector<Biquad> Butterworth(int order, double fc, double fs, bool high) {
  std::vector<Biquad> v;
  for (int k = 0; k < order / 2; ++k) v.push_back(Section(fc, fs, 1.0 / (2.0 * std::sin(kPi * (2 * k + 1) / (2.0 * order))), high));
  return v;
}

double Run(std::vector<Biquad>* f, double x) {
  for (auto& s : *f) x = s.Step(x);
  return x;
}

void ScaleToRms(std::vector<double>* v, double rms) {
  double s = 0;
  for (double x : *v) s += x * x;
  const double r = v->empty() ? 0.0 : std::sqrt(s / static_cast<double>(v->size()));
  if (r > 0)
    for (double& x : *v) x *= rms / r;
}

/// A random walk of n samples from 0, scaled to rms `rms` over the record (0 if rms is 0).
std::vector<double> RandomWalk(std::size_t n, double rms, std::uint64_t seed) {
  std::vector<double> w(n, 0.0);
  if (!(rms > 0) || n < 2) return w;
  auto g = signal::MakeGaussian(seed);
  for (std::size_t k = 1; k < n; ++k) w[k] = w[k - 1] + signal::NextGaussian(&g);
  ScaleToRms(&w, rms);
  return w;
}

/// Raised-cosine fade-in over the first `s` seconds (the record starts at rest).
void FadeIn(std::vector<double>* v, double dt, double s) {
  const auto nf = static_cast<std::size_t>(std::lround(s / dt));
  for (std::size_t k = 0; k < std::min(nf, v->size()); ++k) (*v)[k] *= 0.5 * (1.0 - std::cos(kPi * static_cast<double>(k) / static_cast<double>(nf)));
}

/// Amplitude envelope of the deterministic commands: flat displacement at low frequency, flat
/// velocity above 5 Hz (a rig cannot give 5 mm at 40 Hz).
double Envelope(double f_hz) { return 1.0 / std::sqrt(1.0 + (f_hz / 5.0) * (f_hz / 5.0)); }

std::vector<double> BandNoise(const IndependentExcitation& ex, std::size_t n, signal::GaussianState* g) {
  const double fs = 1.0 / ex.dt_s;
  auto lp = Butterworth(6, ex.hi_hz, fs, false);
  std::vector<Biquad> hp;
  if (ex.lo_hz > 0) hp = Butterworth(2, ex.lo_hz, fs, true);
  const auto warm = static_cast<std::size_t>(std::lround(2.0 / ex.dt_s));
  std::vector<double> u(n);
  for (std::size_t k = 0; k < n + warm; ++k) {
    const double x = Run(&hp, Run(&lp, signal::NextGaussian(g)));
    if (k >= warm) u[k - warm] = x;
  }
  return u;
}

std::vector<double> Chirp(const IndependentExcitation& ex, std::size_t n) {
  const double lo = std::max(ex.lo_hz, 0.1), hi = ex.hi_hz, T = static_cast<double>(n) * ex.dt_s;
  const double r = std::log(hi / lo);
  std::vector<double> u(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * ex.dt_s;
    const double f = lo * std::exp(r * t / T);
    const double phase = 2.0 * kPi * lo * T / r * (std::exp(r * t / T) - 1.0);
    u[k] = Envelope(f) * std::sin(phase);
  }
  // Fade out over the last 0.25 s as well.
  std::reverse(u.begin(), u.end());
  FadeIn(&u, ex.dt_s, 0.25);
  std::reverse(u.begin(), u.end());
  return u;
}

std::vector<double> Multisine(const IndependentExcitation& ex, std::size_t n, signal::GaussianState* g) {
  const double T = static_cast<double>(n) * ex.dt_s, df = 1.0 / T;
  const double lo = std::max(ex.lo_hz, df), hi = ex.hi_hz;
  std::vector<double> fr;
  const int K = 40;
  for (int j = 0; j < K; ++j) {
    const double f = lo * std::pow(hi / lo, j / (K - 1.0));
    const double fq = std::max(1.0, std::round(f / df)) * df;  // a whole number of periods
    if (fr.empty() || fq > fr.back() + 0.5 * df) fr.push_back(fq);
  }
  std::vector<double> u(n, 0.0);
  for (double f : fr) {
    const double ph = 2.0 * kPi * signal::NextUniform(g), a = Envelope(f);
    // Rotation recurrence instead of one sin per sample.
    const double c = std::cos(2.0 * kPi * f * ex.dt_s), s = std::sin(2.0 * kPi * f * ex.dt_s);
    double re = std::cos(ph), im = std::sin(ph);
    for (std::size_t k = 0; k < n; ++k) {
      u[k] += a * im;
      const double r2 = re * c - im * s;
      im = re * s + im * c;
      re = r2;
    }
  }
  return u;
}

/// The relative displacement of an SDOF (f_n = ex.lo_hz, zeta 3 %) under El Centro: the command of
/// an RTHS-like test. RK4 at dt, the ground acceleration interpolated linearly, zero after its end.
std::vector<double> Earthquake(const IndependentExcitation& ex, std::size_t n) {
  const auto& ag = ex.ground_g;
  if (ag.size() < 10) throw Error("independent rig", "an earthquake command needs the ground motion (IndependentExcitation::ground_g)");
  const double g_mm = 9806.65, dtg = 0.02;
  const double w = 2.0 * kPi * (ex.lo_hz > 0 ? ex.lo_hz : 2.0), zeta = 0.03;
  auto acc = [&](double t) {
    const double j = t / dtg;
    const auto j0 = static_cast<std::size_t>(std::floor(j));
    if (j0 + 1 >= ag.size()) return 0.0;
    const double a = j - static_cast<double>(j0);
    return g_mm * ((1.0 - a) * ag[j0] + a * ag[j0 + 1]);
  };
  auto rhs = [&](double t, double x, double v, double* dx, double* dv) {
    *dx = v;
    *dv = -acc(t) - 2.0 * zeta * w * v - w * w * x;
  };
  std::vector<double> u(n);
  double x = 0, v = 0;
  const double h = ex.dt_s;
  for (std::size_t k = 0; k < n; ++k) {
    u[k] = x;
    const double t = static_cast<double>(k) * h;
    double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
    rhs(t, x, v, &k1x, &k1v);
    rhs(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v, &k2x, &k2v);
    rhs(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v, &k3x, &k3v);
    rhs(t + h, x + h * k3x, v + h * k3v, &k4x, &k4v);
    x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  return u;
}

std::vector<double> Pattern(const IndependentExcitation& ex, std::size_t n, signal::GaussianState* g);

/// The current command: the pattern, on at current_start_A from the first sample until the pattern
/// first changes (IndependentExcitation::current_start_A).
std::vector<double> Current(const IndependentExcitation& ex, std::size_t n, signal::GaussianState* g) {
  std::vector<double> i = Pattern(ex, n, g);
  if (ex.current_start_A > 0.0 && !i.empty()) {
    std::size_t k1 = 1;
    while (k1 < n && i[k1] == i[0]) ++k1;
    std::fill(i.begin(), i.begin() + static_cast<std::ptrdiff_t>(k1), ex.current_start_A);
  }
  return i;
}

std::vector<double> Pattern(const IndependentExcitation& ex, std::size_t n, signal::GaussianState* g) {
  std::vector<double> i(n, 0.0);
  const double P = std::max(ex.current_period_s, 10.0 * ex.dt_s), I = ex.current_max_A;
  switch (ex.current) {
    case CurrentPattern::kConstant:
      std::fill(i.begin(), i.end(), I);
      break;
    case CurrentPattern::kPulsed: {
      const double phase = P * signal::NextUniform(g);
      for (std::size_t k = 0; k < n; ++k) {
        const double t = static_cast<double>(k) * ex.dt_s + phase;
        i[k] = std::fmod(t, P) < 0.5 * P ? I : 0.0;
      }
      break;
    }
    case CurrentPattern::kStaircase: {
      // 0, 1, .., 5, 4, .., 1, 0, 1, ... fifths of I, each held P.
      for (std::size_t k = 0; k < n; ++k) {
        const auto step = static_cast<long>(std::floor(static_cast<double>(k) * ex.dt_s / P));
        const long m = step % 10;
        i[k] = I * static_cast<double>(m <= 5 ? m : 10 - m) / 5.0;
      }
      break;
    }
    case CurrentPattern::kTelegraph: {
      bool on = signal::NextUniform(g) < 0.5;
      std::size_t k = 0;
      while (k < n) {
        const double hold = std::max(0.05, -P * std::log(std::max(1e-12, 1.0 - signal::NextUniform(g))));
        const auto m = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(hold / ex.dt_s)));
        for (std::size_t j = k; j < std::min(n, k + m); ++j) i[j] = on ? I : 0.0;
        k += m;
        on = !on;
      }
      break;
    }
  }
  return i;
}

// ------------------------------------------------------------------------------------------
// The continuous rig

enum : int { kW, kX, kXv, kQ, kQv, kR, kYl, kPhi, kPs, kYb, kYd, kZ, kM, kIc, kIcv, kL1, kL2, kStates };
using State = std::array<double, kStates>;

struct Outputs {
  double y_mm, yv_mm_s, f_kN;
  double ya_mm_s2;  ///< the specimen's acceleration as the effect chain knows it (load_cell_inertia)
  double lambda;  ///< a bound of the local Jacobian's size [1/s]
};

class ContinuousRig {
 public:
  ContinuousRig(const IndependentTruth& t, double duration_s)
      : t_(t), duration_s_(duration_s), d_(models::MrDamperParams::Table3()) {
    const models::ServoModel3 m = models::ServoPreset("avg");
    K_ = m.K, p_ = m.p, b_ = m.b, c_ = m.c;
    oil_ = t.oil_f_hz > 0, sat_ = t.vmax_mm_per_s > 0 && !t.vmax_in_loop, loop_sat_ = t.vmax_mm_per_s > 0 && t.vmax_in_loop,
    lc_ = t.compliance_mm_per_kN > 0;
    fr_ = t.friction_loss_mm > 0, bl_ = t.backlash_gap_mm > 0, lag_ = t.current_lag_ms > 0;
    ps_ = t.presliding_loss_mm > 0;
    if (lc_ && (fr_ || bl_))
      throw Error("independent rig", "load_coupling with coulomb_friction or backlash is not modelled");
    if (ps_ && !(t.presliding_rho > 0 && t.presliding_rho <= 1)) throw Error("independent rig", "presliding_rho must be in (0, 1]");
    w_oil_ = 2.0 * kPi * t.oil_f_hz;
    tau1_ = 0.8e-3 * t.current_lag_ms, tau2_ = 0.2e-3 * t.current_lag_ms;
    h_ = 0.5 * t.backlash_gap_mm, wb_ = 0.3 * h_;
  }

  /// Rest at the current command i0 [A] (the current's states at their steady state).
  State Rest(double i0) const {
    State s{};
    s[kL1] = s[kL2] = i0;
    s[kM] = i0 / a_;
    s[kIc] = i0;
    return s;
  }

  /// ds = f(s) with the servo command us [mm] and the current command id [A] held; the outputs at s.
  Outputs Deriv(const State& s, double us, double id, double time_s, State* ds) const {
    ds->fill(0.0);
    State& d = *ds;
    double lam = 0.0;
    // Servo, cascade form; a valve overlap acts on the continuous loop error u - x.
    if (t_.dead_band_mm > 0) {
      const double h = 0.5 * t_.dead_band_mm, e = us - s[kX];
      us = s[kX] + e - h * std::tanh(e / h);
    }
    d[kW] = -p_ * s[kW] + K_ * us;
    // A flow limit inside the loop: the piston's velocity is the loop's velocity state, saturated.
    d[kX] = loop_sat_ ? SmoothSat(s[kXv], t_.vmax_mm_per_s) : s[kXv];
    d[kXv] = s[kW] - b_ * s[kXv] - c_ * s[kX];
    // The pump's flow ripple enters the piston's chamber: the oil column's state when it has one.
    const double pump = t_.pump_hz > 0 ? PumpFlow(time_s) : 0.0;
    if (!oil_) d[kX] += pump;
    double y = s[kX], yv = d[kX];
    double ya = d[kXv];  // the acceleration of y where the chain knows it (for the friction's step size)
    if (oil_) {
      d[kQ] = s[kQv] + pump;
      d[kQv] = w_oil_ * w_oil_ * (y - s[kQ]) - 2.0 * t_.oil_zeta * w_oil_ * s[kQv];
      y = s[kQ], yv = d[kQ], ya = d[kQv];
    }
    if (sat_) {
      const double vm = t_.vmax_mm_per_s, tau_r = 1e-3;
      const double v = SmoothSat(yv + (y - s[kR]) / tau_r, vm);
      d[kR] = v;
      ya = (v - yv) / tau_r;  // where the limit does not act, the error's rate
      y = s[kR], yv = v;
      lam = std::max(lam, 1.0 / tau_r);
    }
    // Current: the lag, Eq. 40, the 75 Hz low-pass.
    double il = id;
    if (lag_) {
      d[kL1] = (id - s[kL1]) / tau1_;
      d[kL2] = (s[kL1] - s[kL2]) / tau2_;
      il = s[kL2];
    }
    d[kM] = -a_ * s[kM] + il;
    const double i40 = (a_ / b9_) * (il + (b9_ - a_) * s[kM]);
    d[kIc] = s[kIcv];
    d[kIcv] = wn_ * wn_ * (i40 - s[kIc]) - 2.0 * zn_ * wn_ * s[kIcv];
    // Eqs. 35-39 at i_c, scaled by damper_scale (alpha, c0, c1, k0: exactly a force scale).
    const double ic = s[kIc];
    auto at = [ic](double pa, double pb, double pc) { return pb + (pa - pb) * std::exp(-pc * ic); };
    const double S = Scale(time_s);
    const double alpha = S * at(d_.alpha_a, d_.alpha_b, d_.alpha_c), c0 = S * at(d_.c0_a, d_.c0_b, d_.c0_c),
                 c1 = S * at(d_.c1_a, d_.c1_b, d_.c1_c), k0 = S * d_.k0;
    const double beta = at(d_.beta_a, d_.beta_b, d_.beta_c), gamma = at(d_.gamma_a, d_.gamma_b, d_.gamma_c);
    const double z = s[kZ], yd = s[kYd];
    if (lc_) {
      // yl = x - c F, the specimen at yf = yl - phi (presliding after the compliance, phi = 0
      // without it) with F = c1/(c0+c1) (alpha z + k0 (yf - yd)) + B yf' + k1 (yf - x0) + extra(yf)
      // = P + B yf', yf' = g yl' (g = 1 - sigma base^1.5, the presliding law's slope, > 0).
      const double yl = s[kYl], cc = t_.compliance_mm_per_kN;
      const double phi = ps_ ? s[kPs] : 0.0, yf = yl - phi;
      const double P = c1 / (c0 + c1) * (alpha * z + k0 * (yf - yd)) + d_.k1 * (yf - d_.x0) + Extra(yf);
      const double B = c0 * c1 / (c0 + c1);
      const double num = (y - yl) / cc - P;  // B yf', whose sign is yl''s
      double g = 1.0;
      if (ps_) {
        const double L = t_.presliding_loss_mm, sigma = t_.presliding_rho / std::pow(2.0, 1.5);
        const double sg = num > 0 ? 1.0 : num < 0 ? -1.0 : 0.0;
        g = 1.0 - sigma * std::pow(std::clamp(1.0 - phi * sg / L, 0.0, 2.0), 1.5);
      }
      const double v = num / (B * g);
      d[kYl] = v;
      y = yl, yv = v, ya = 0.0;
      lam = std::max(lam, 1.0 / (cc * B * g));
    }
    if (fr_) {
      const double vs = 1.5, tau_f = 0.3e-3;
      const double dphi = (t_.friction_loss_mm * (2.0 / kPi) * std::atan(yv / vs) - s[kPhi]) / tau_f;
      d[kPhi] = dphi;
      y -= s[kPhi], yv -= dphi;
      // The lag, and the sign law's own time scale at a reversal, |y''| / v_s.
      lam = std::max(lam, std::max(1.0 / tau_f, std::abs(ya) / vs));
    }
    if (ps_) {
      const double L = t_.presliding_loss_mm, sigma = t_.presliding_rho / std::pow(2.0, 1.5);
      const double sg = yv > 0 ? 1.0 : yv < 0 ? -1.0 : 0.0;
      const double base = std::clamp(1.0 - s[kPs] * sg / L, 0.0, 2.0);
      const double dps = sigma * yv * std::pow(base, 1.5);
      d[kPs] = dps;
      // |d dps / d phi| at the input's velocity, before the output's replaces it.
      lam = std::max(lam, 1.5 * sigma * std::abs(yv) * std::sqrt(base) / L);
      y -= s[kPs], yv -= dps;
    }
    if (bl_) {
      const double e = y - s[kYb];
      const double g = e * yv > 0 ? std::clamp((std::abs(e) - (h_ - wb_)) / wb_, 0.0, 1.0) : 0.0;
      d[kYb] = yv * g;
      lam = std::max(lam, std::abs(yv) / wb_);
      y = s[kYb], yv = d[kYb];
    }
    // The damper, Eqs. 32-34.
    const double ydv = (alpha * z + k0 * (y - yd) + c0 * yv) / (c0 + c1);
    const double rel = yv - ydv;
    const double n = d_.n;
    const double zn1 = n == 2.0 ? std::abs(z) : std::pow(std::abs(z), n - 1.0);
    d[kYd] = ydv;
    d[kZ] = -gamma * std::abs(rel) * z * zn1 - beta * rel * std::abs(z) * zn1 + d_.A * rel;
    const double f = alpha * z + c0 * rel + k0 * (y - yd) + d_.k1 * (y - d_.x0) + Extra(y);
    lam = std::max(lam, (beta + gamma) * n * zn1 * std::abs(rel) + d_.A * alpha / (c0 + c1));
    return {y, yv, f, ya, lam};
  }

  /// m RK4 steps of h from time t0, inputs held.
  void Rk4(State* s, double us, double id, double t0, double h, int m) const {
    State k1, k2, k3, k4, x;
    for (int j = 0; j < m; ++j) {
      const double t = t0 + j * h;
      Deriv(*s, us, id, t, &k1);
      for (int q = 0; q < kStates; ++q) x[q] = (*s)[q] + 0.5 * h * k1[q];
      Deriv(x, us, id, t + 0.5 * h, &k2);
      for (int q = 0; q < kStates; ++q) x[q] = (*s)[q] + 0.5 * h * k2[q];
      Deriv(x, us, id, t + 0.5 * h, &k3);
      for (int q = 0; q < kStates; ++q) x[q] = (*s)[q] + h * k3[q];
      Deriv(x, us, id, t + h, &k4);
      for (int q = 0; q < kStates; ++q) (*s)[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
    }
  }

  /// The command the servo sees from the record's command u_k (gain, asymmetric valve).
  double ServoCommand(double u) const {
    const double a = t_.asymmetric_gain;
    return t_.gain * u * (u > 0 ? 1.0 + a : 1.0 - a);
  }

 private:
  double Scale(double time_s) const {
    if (t_.damper_scale == 1.0) return 1.0;
    return t_.damper_scale * (1.0 + t_.damper_scale_drift * (time_s / duration_s_ - 0.5));
  }
  /// vmax sat(v / vmax), sat(q) = q / (1 + |q|^8)^(1/8).
  static double SmoothSat(double v, double vmax) {
    const double q = v / vmax;
    return vmax * q / std::pow(1.0 + std::pow(std::abs(q), 8.0), 0.125);
  }
  double Extra(double y) const { return t_.cubic_kN_per_mm3 * y * y * y; }
  /// supply_ripple's velocity disturbance [mm/s] at time_s (file comment).
  double PumpFlow(double time_s) const {
    const double fw = 0.1, w = t_.pump_wander;
    const double theta = 2.0 * kPi * t_.pump_hz * (time_s + w * std::sin(2.0 * kPi * fw * time_s) / (2.0 * kPi * fw));
    const double theta_v = 2.0 * kPi * t_.pump_hz * (1.0 + w * std::cos(2.0 * kPi * fw * time_s));
    const double a[3] = {1.0, t_.pump_h2, t_.pump_h3}, ph[3] = {0.0, t_.pump_phase2, t_.pump_phase3};
    double q = 0.0;
    for (int h = 0; h < 3; ++h) q += t_.pump_mm * a[h] * (h + 1) * theta_v * std::cos((h + 1) * theta + ph[h]);
    return q;
  }

  IndependentTruth t_;
  double duration_s_;
  models::MrDamperParams d_;
  double K_ = 0, p_ = 0, b_ = 0, c_ = 0;
  const double a_ = kPi, b9_ = 9.0 * kPi, wn_ = 2.0 * kPi * 75.0, zn_ = 1.0 / std::sqrt(2.0);
  bool loop_sat_ = false;
  bool oil_ = false, sat_ = false, lc_ = false, fr_ = false, bl_ = false, lag_ = false, ps_ = false;
  double w_oil_ = 0, tau1_ = 0, tau2_ = 0, h_ = 0, wb_ = 0;
};

}  // namespace

std::vector<double> ReadGroundMotion(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string(), "cannot read the ground-motion record");
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  if (v.size() < 10) throw Error(file.string(), "too few samples in the ground-motion record");
  return v;
}

void MakeIndependentInputs(const IndependentExcitation& ex, std::vector<double>* u_mm, std::vector<double>* i_A) {
  if (!(ex.dt_s > 0) || !(ex.duration_s > 0)) throw Error("independent rig", "duration and dt must be > 0");
  const auto n = static_cast<std::size_t>(std::lround(ex.duration_s / ex.dt_s));
  const double nyq = 0.5 / ex.dt_s;
  if (ex.command != CommandFamily::kEarthquake && !(ex.hi_hz > ex.lo_hz && ex.hi_hz < 0.9 * nyq))
    throw Error("independent rig", fmt::format("band {}-{} Hz is not inside (0, 0.9 f_Nyquist)", ex.lo_hz, ex.hi_hz));
  auto g = signal::MakeGaussian(ex.seed * 0x9E3779B97F4A7C15ULL + 0x1234567ULL);
  switch (ex.command) {
    case CommandFamily::kBandNoise: *u_mm = BandNoise(ex, n, &g); break;
    case CommandFamily::kChirp: *u_mm = Chirp(ex, n); break;
    case CommandFamily::kMultisine: *u_mm = Multisine(ex, n, &g); break;
    case CommandFamily::kEarthquake: *u_mm = Earthquake(ex, n); break;
  }
  ScaleToRms(u_mm, ex.rms_mm);
  FadeIn(u_mm, ex.dt_s, 0.25);
  auto gi = signal::MakeGaussian(ex.seed * 0xD1B54A32D192ED03ULL + 99);
  *i_A = Current(ex, n, &gi);
}

IndependentTraces SimulateIndependent(const std::vector<double>& u, const std::vector<double>& i, double dt,
                                      const IndependentTruth& truth) {
  if (u.size() != i.size() || u.empty()) throw Error("independent rig", "u and i must have the same, non-zero length");
  if (truth.substeps < 1) throw Error("independent rig", "substeps must be >= 1");
  if (!std::isfinite(truth.skew_ms) || std::abs(truth.skew_ms) > 100.0)
    throw Error("independent rig", "skew_ms must be in [-100, 100]");
  const std::size_t n = u.size();
  const ContinuousRig rig(truth, static_cast<double>(n) * dt);
  IndependentTraces out;
  out.y_mm.resize(n);
  out.f_kN.resize(n);
  State s = rig.Rest(truth.driver_at_rest ? 0.0 : i[0]), ds;
  // The delay: tau = (m + phi) dt; over step k the servo sees u_{k-m-1} until t_k + phi dt, then u_{k-m}.
  const double tau_s = std::max(0.0, truth.delay_ms) * 1e-3;
  auto m = static_cast<long>(std::floor(tau_s / dt));
  double phi = tau_s / dt - static_cast<double>(m);
  if (phi > 1.0 - 1e-9) ++m, phi = 0.0;
  if (phi < 1e-9) phi = 0.0;
  // The skew: the force recorded at t_k is the load cell's at t_k - (D + e) dt, e in [0, 1): for
  // e > 0, inside step j at tau = (1 - e) dt, recorded as sample j + D + 1; for e = 0, sample j + D.
  const double skew = 1e-3 * truth.skew_ms / dt;
  auto D = static_cast<long>(std::floor(skew));
  double e = skew - static_cast<double>(D);
  if (e > 1.0 - 1e-9) ++D, e = 0.0;
  if (e < 1e-9) e = 0.0;
  std::vector<double> cell(n), skewed(n, std::nan(""));  // the load cell's force at t_k; at t_k - skew
  auto cell_force = [&](const Outputs& o) { return o.f_kN + 1e-6 * truth.cell_mass_kg * o.ya_mm_s2; };
  auto cmd = [&](long j) { return j < 0 ? 0.0 : rig.ServoCommand(u[static_cast<std::size_t>(j)]); };
  const double sub = static_cast<double>(truth.substeps);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    const Outputs o = rig.Deriv(s, cmd(static_cast<long>(k) - m), i[k], t, &ds);
    out.y_mm[k] = o.y_mm;
    cell[k] = cell_force(o);
    if (k + 1 == n) break;
    // Substeps for this record step: at least `substeps`, and h lambda <= 8 / substeps.
    const double need = std::ceil(sub * dt * o.lambda / 8.0);
    const int M = static_cast<int>(std::clamp(std::max(sub, need), 1.0, 65536.0));
    out.substeps_max = std::max<std::size_t>(out.substeps_max, static_cast<std::size_t>(M));
    const long j = static_cast<long>(k) - m;
    // The step's pieces: split where the delayed command switches (phi dt) and where the skewed
    // force is taken ((1 - e) dt); each piece gets its share of the M substeps.
    double cuts[4] = {0.0, 0.0, 0.0, 1.0};
    int nc = 1;
    if (phi > 0.0) cuts[nc++] = phi;
    if (e > 0.0) cuts[nc++] = 1.0 - e;
    std::sort(cuts + 1, cuts + nc);
    cuts[nc] = 1.0;
    for (int q = 0; q < nc; ++q) {
      const double a = cuts[q], b = cuts[q + 1];
      if (b - a > 1e-12) {
        const int mq = std::max(1, static_cast<int>(std::ceil(M * (b - a))));
        rig.Rk4(&s, cmd(a < phi ? j - 1 : j), i[k], t + a * dt, (b - a) * dt / mq, mq);
      }
      if (e > 0.0 && b == 1.0 - e) {  // the skewed force of sample k + D + 1
        const long target = static_cast<long>(k) + D + 1;
        if (target >= 0 && target < static_cast<long>(n)) {
          State dd;
          const double tb = t + b * dt;
          skewed[static_cast<std::size_t>(target)] = cell_force(rig.Deriv(s, cmd(b < phi ? j - 1 : j), i[k], tb, &dd));
        }
      }
    }
    for (double v : s)
      if (!std::isfinite(v))
        throw Error("independent rig", fmt::format("the simulation diverged at t = {} s", t + dt));
  }
  // Recorded force: the skewed samples; e = 0 (or no skew) the load cell's own samples D back; before
  // the record (skew > 0) the force at rest, after it (skew < 0) the last one.
  for (std::size_t k = 0; k < n; ++k) {
    if (e > 0.0 && !std::isnan(skewed[k])) {
      out.f_kN[k] = skewed[k];
      continue;
    }
    const long src = static_cast<long>(k) - D - (e > 0.0 ? 1 : 0);
    out.f_kN[k] = cell[static_cast<std::size_t>(std::clamp<long>(src, 0, static_cast<long>(n) - 1))];
  }
  return out;
}

std::vector<double> IndependentNoise(std::size_t n, double dt, double rms, NoiseColour colour, double drift_fraction,
                                     std::uint64_t seed) {
  std::vector<double> v(n, 0.0);
  if (!(rms > 0) || n == 0) return v;
  auto g = signal::MakeGaussian(seed);
  if (colour == NoiseColour::kWhite) {
    for (double& x : v) x = signal::NextGaussian(&g);
  } else {
    // White at 8x the record rate, a 4th-order Butterworth anti-alias filter at 0.4 / dt, sampled.
    const int over = 8;
    auto lp = Butterworth(4, 0.4 / dt, over / dt, false);
    const std::size_t warm = 400;
    for (std::size_t k = 0; k < (n + warm) * over; ++k) {
      const double x = Run(&lp, signal::NextGaussian(&g));
      if (k % over == 0 && k / over >= warm) v[k / over - warm] = x;
    }
  }
  ScaleToRms(&v, rms);
  if (drift_fraction > 0) {
    const double fd = 0.02 + 0.08 * signal::NextUniform(&g), ph = 2.0 * kPi * signal::NextUniform(&g);
    for (std::size_t k = 0; k < n; ++k)
      v[k] += drift_fraction * rms * std::sin(2.0 * kPi * fd * static_cast<double>(k) * dt + ph);
  }
  return v;
}

io::RigRecord MakeIndependentRecord(const IndependentExcitation& ex, const IndependentTruth& truth,
                                    const std::string& name) {
  io::RigRecord r;
  MakeIndependentInputs(ex, &r.u_mm, &r.i_A);
  const std::size_t n = r.u_mm.size();
  const auto tr = SimulateIndependent(r.u_mm, r.i_A, ex.dt_s, truth);
  r.dt_s = ex.dt_s;
  r.source = name;
  r.t_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) r.t_s[k] = static_cast<double>(k) * ex.dt_s;
  const auto ny = IndependentNoise(n, ex.dt_s, truth.noise_y_mm, truth.colour, truth.drift_fraction, truth.noise_seed);
  const auto nf = IndependentNoise(n, ex.dt_s, truth.noise_f_kN, truth.colour, truth.drift_fraction,
                                   truth.noise_seed * 0x2545F4914F6CDD1DULL + 5);
  const auto wy = RandomWalk(n, truth.walk_fraction * truth.noise_y_mm, truth.noise_seed * 31 + 1);
  const auto wf = RandomWalk(n, truth.walk_fraction * truth.noise_f_kN, truth.noise_seed * 37 + 2);
  r.y_mm.resize(n);
  r.f_kN.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = r.t_s[k];
    const double ripple = truth.ripple_mm * (1.0 + 0.5 * std::sin(2.0 * kPi * 0.3 * t)) * std::sin(2.0 * kPi * truth.ripple_hz * t);
    r.y_mm[k] = tr.y_mm[k] + ripple + ny[k] + wy[k];
    r.f_kN[k] = tr.f_kN[k] + nf[k] + wf[k];
  }
  r.metadata.push_back({"generator", "validation::MakeIndependentRecord (continuous RK4, independent forms)"});
  r.metadata.push_back({"command", fmt::format("{} {}-{} Hz, {} mm rms", Name(ex.command), ex.lo_hz, ex.hi_hz, ex.rms_mm)});
  r.metadata.push_back({"current", fmt::format("{} {} A, period {} s", Name(ex.current), ex.current_max_A, ex.current_period_s)});
  io::ValidateRigRecord(r, name);
  return r;
}

}  // namespace rths::validation
