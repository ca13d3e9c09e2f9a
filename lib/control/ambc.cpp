#include "control/ambc.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "control/ats.h"
#include "core/error.h"

namespace rths::control {

namespace {

constexpr double kMmToM = 1e-3;
constexpr double kMaxGainLog10 = 30.0;

std::string Quad(const std::array<double, 4>& v) { return fmt::format("[{}, {}, {}, {}]", v[0], v[1], v[2], v[3]); }

void CheckAmbcBounds(const AmbcConfig& cfg) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    if (std::isnan(cfg.lower[i]) || cfg.lower[i] == inf) {
      throw Error("controller.ambc.lower", fmt::format("{}: allowed a number or -inf (not NaN, not +inf)", Quad(cfg.lower)));
    }
    if (std::isnan(cfg.upper[i]) || cfg.upper[i] == -inf) {
      throw Error("controller.ambc.upper", fmt::format("{}: allowed a number or +inf (not NaN, not -inf)", Quad(cfg.upper)));
    }
    if (!(cfg.lower[i] <= cfg.upper[i])) {
      throw Error("controller.ambc.lower", fmt::format("{} (upper {}): allowed lower[i] <= upper[i] (a{} breaks it)",
                                                       Quad(cfg.lower), Quad(cfg.upper), i));
    }
  }
}

/// theta(0) of `start`, inside the bounds.
std::array<double, 4> InitialTheta(const AmbcConfig& cfg, const models::ServoModel3& model) {
  if (cfg.start == AmbcStart::kGiven) {
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(cfg.initial[i]) || cfg.initial[i] < cfg.lower[i] || cfg.initial[i] > cfg.upper[i]) {
        throw Error("controller.ambc.initial",
                    fmt::format("{}: a{} = {}; allowed finite within [lower, upper] = [{}, {}]", Quad(cfg.initial),
                                i, cfg.initial[i], cfg.lower[i], cfg.upper[i]));
      }
    }
    return cfg.initial;
  }
  const FeedforwardCoefficients a = FeedforwardFor(model, "controller.model");
  const std::array<double, 4> theta{a.a0, a.a1, a.a2, a.a3};
  for (int i = 0; i < 4; ++i) {
    if (theta[i] < cfg.lower[i] || theta[i] > cfg.upper[i]) {
      throw Error(theta[i] < cfg.lower[i] ? "controller.ambc.lower" : "controller.ambc.upper",
                  fmt::format("start = \"model\": controller.model's Eq. 19 coefficients {} put a{} = {} outside "
                              "[lower, upper] = [{}, {}]; allowed bounds that contain them",
                              Quad(theta), i, theta[i], cfg.lower[i], cfg.upper[i]));
    }
  }
  return theta;
}

std::array<double, 4> Saturate(const AmbcConfig& cfg, const std::array<double, 4>& theta) {
  std::array<double, 4> s;
  for (int i = 0; i < 4; ++i) s[i] = std::min(std::max(theta[i], cfg.lower[i]), cfg.upper[i]);
  return s;
}

/// [x_k, D1 x_k, D2 x_k, D3 x_k] from x_k and x_k-1 .. x_k-3 (backward differences).
std::array<double, 4> BackwardDifferences(double x, const std::array<double, 3>& past, double dt) {
  const double dt2 = dt * dt;
  return {x, (x - past[0]) / dt, (x - 2.0 * past[0] + past[1]) / dt2,
          (x - 3.0 * past[0] + 3.0 * past[1] - past[2]) / (dt2 * dt)};
}

void Push(std::array<double, 3>* past, double x) { *past = {x, (*past)[0], (*past)[1]}; }

}  // namespace

AmbcDesign MakeAmbcDesign(const AmbcConfig& cfg, const models::ServoModel3& model, double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw Error("run.dt_s", fmt::format("{}: allowed > 0", dt_s));
  CheckAmbcBounds(cfg);
  AmbcDesign d;
  d.config = cfg;
  d.dt_s = dt_s;
  d.initial = InitialTheta(cfg, model);
  for (int i = 0; i < 4; ++i) {
    const double g = cfg.gain_log10[i];
    const bool off = g == -std::numeric_limits<double>::infinity();
    if (!off && !(g >= -kMaxGainLog10 && g <= kMaxGainLog10)) {
      throw Error("controller.ambc.gain_log10",
                  fmt::format("{}: allowed [{}, {}] each, or -inf (that coefficient is not adapted)",
                              Quad(cfg.gain_log10), -kMaxGainLog10, kMaxGainLog10));
    }
    d.gamma[i] = off ? 0.0 : std::pow(10.0, g);
  }
  if (cfg.filter_order < 1 || cfg.filter_order > kMaxAdaptiveFilterOrder) {
    throw Error("controller.ambc.filter_order",
                fmt::format("{}: allowed [1, {}]", cfg.filter_order, kMaxAdaptiveFilterOrder));
  }
  if (!(cfg.filter_hz > 0.0 && cfg.filter_hz < 0.5 / dt_s)) {
    throw Error("controller.ambc.filter_hz",
                fmt::format("{} Hz: allowed (0, {}) Hz (below the Nyquist frequency 0.5/run.dt_s)", cfg.filter_hz,
                            0.5 / dt_s));
  }
  d.filter = signal::ButterworthLowpass(cfg.filter_order, cfg.filter_hz, 1.0 / dt_s);
  return d;
}

AmbcState AmbcAtRest(const AmbcDesign& d) {
  AmbcState s;
  s.filter_y = signal::SosAtRest(d.filter);
  s.filter_u = signal::SosAtRest(d.filter);
  s.theta = d.initial;
  s.theta_used = d.initial;
  return s;
}

Command AmbcCommand(const AmbcDesign& d, AmbcState* s, const Derivatives& target) {
  const std::array<double, 4> phi_t = d.config.derivatives == TargetDerivatives::kDifference
                                          ? BackwardDifferences(target.r, s->r_past_mm, d.dt_s)
                                          : std::array<double, 4>{target.r, target.rd, target.rdd, target.rddd};
  Push(&s->r_past_mm, target.r);
  s->theta_used = Saturate(d.config, s->theta);
  double u = 0.0;
  for (int i = 0; i < 4; ++i) u += s->theta_used[i] * phi_t[i];
  s->u_mm = u;
  Command c;
  c.u_mm = c.u_ff_mm = u;
  c.u_fb_mm = 0.0;
  c.n_adapt = 4;
  c.adapt = s->theta_used;
  return c;
}

void AmbcUpdate(const AmbcDesign& d, AmbcState* s, double y_mm) {
  const double yf = signal::SosStep(d.filter, &s->filter_y, y_mm * kMmToM);
  s->z_m = signal::SosStep(d.filter, &s->filter_u, s->u_mm * kMmToM);
  s->phi = BackwardDifferences(yf, s->yf_past_m, d.dt_s);
  Push(&s->yf_past_m, yf);
  s->eps = IntegrateGradientLaw(d, s->phi, s->z_m, &s->theta);
}

double IntegrateGradientLaw(const AmbcDesign& d, const std::array<double, 4>& phi, double z_m,
                            std::array<double, 4>* theta) {
  const AmbcConfig& cfg = d.config;
  double m2 = 1.0, e0 = z_m, mu = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double th = (*theta)[i];
    const bool free = th >= cfg.lower[i] && th <= cfg.upper[i];
    m2 += phi[i] * phi[i];
    e0 -= std::min(std::max(th, cfg.lower[i]), cfg.upper[i]) * phi[i];
    if (free) mu += d.gamma[i] * phi[i] * phi[i];
  }
  mu /= m2;
  // integral of exp(-mu t) over [0, dt], accurate for small mu dt.
  const double x = mu * d.dt_s;
  const double integral = x > 0.0 ? d.dt_s * (-std::expm1(-x) / x) : d.dt_s;
  const double step = e0 / m2 * integral;
  for (int i = 0; i < 4; ++i) (*theta)[i] += d.gamma[i] * phi[i] * step;
  return e0 / m2;
}

ControllerLti AmbcController::Linearize(double) const {
  return {AdaptiveFir(design_.initial, design_.config.derivatives, design_.dt_s), false, {}};
}

}  // namespace rths::control
