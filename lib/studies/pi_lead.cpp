// pi_lead (studies/pi_lead.h): a PI feedback and a phase lead on the reference, designed for a
// servohydraulic model by the rule of docs/reproduce_table2.md, in the manner of the RTHS benchmark's
// example controller.
#include "studies/pi_lead.h"

#include <cmath>
#include <complex>
#include <numbers>

#include <fmt/format.h>

#include "control/analysis.h"
#include "control/lti.h"
#include "control/lti_controller.h"
#include "core/error.h"

namespace rths::studies {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

/// The Tustin PI's response at f: Kp + Ki (dt/2)(z + 1)/(z - 1) = Kp - j Ki h, h = (dt/2) cot(w dt/2).
double TustinIntegratorGain(double f_hz, double dt_s) {
  const double half = kPi * f_hz * dt_s;  // w dt / 2
  return 0.5 * dt_s / std::tan(half);
}

/// The PI that gives the loop |L| = 1 and the phase margin pm_rad at f, from the plant's response
/// there (g) and its phase unwrapped from 0 Hz (theta). Kp < 0 or Ki <= 0 when the margin cannot be
/// had at f with a PI (the plant's phase outside (-180 + pm, -90 + pm)).
struct PiAt {
  double kp = 0.0, ki = 0.0;
};
PiAt PiForMargin(std::complex<double> g, double theta, double pm_rad, double f_hz, double dt_s) {
  const double phc = -kPi + pm_rad - theta;  // arg C needed
  const double mag = std::abs(g);
  return {std::cos(phc) / mag, -std::sin(phc) / (mag * TustinIntegratorGain(f_hz, dt_s))};
}

control::LtiConfig PiLeadLti(double kp, double ki, bool with_lead, double k, double zero, double pole) {
  control::LtiConfig c;
  c.feedback = {{kp, ki}, {1.0, 0.0}};
  if (with_lead) c.reference = {{k, -k * zero}, {1.0, -pole}};
  c.domain = control::TfDomain::kS;
  c.discretisation = control::Discretisation::kTustin;
  return c;
}

control::ControllerLti Linearized(const control::LtiConfig& cfg, double dt_s) {
  return control::LtiController(control::MakeLtiDesign(cfg, dt_s)).Linearize(0.0);
}

/// (1) The PI: for every crossover frequency f of the grid, the Kp, Ki that give the margin there;
/// of those whose loop has a peak sensitivity <= max_sensitivity, the largest Ki. The plant's
/// phase is unwrapped from the lowest frequency of the grid up (the ZOH model's phase passes
/// -180 deg below Nyquist); the sensitivity is evaluated on the same grid. Throws rths::Error if
/// no PI of the grid meets the margin and the bound.
void ChoosePi(const control::DiscreteSs& g, double dt_s, PiLeadDesign* out) {
  PiLeadDesign& d = *out;
  const double pm = d.target_pm_deg * kDeg;
  const double f_lo = 0.1, f_hi = 0.45 / dt_s;
  const int n = 6000;
  std::vector<double> f(n + 1), theta(n + 1), hint(n + 1);
  std::vector<std::complex<double>> gr(n + 1);
  for (int i = 0; i <= n; ++i) {
    f[i] = f_lo * std::pow(f_hi / f_lo, static_cast<double>(i) / n);
    gr[i] = g.Response(f[i]);
    theta[i] = i == 0 ? std::arg(gr[0]) : theta[i - 1] + std::arg(gr[i] / gr[i - 1]);
    hint[i] = TustinIntegratorGain(f[i], dt_s);
  }
  const double max_s = std::pow(10.0, d.max_sensitivity_db / 20.0);
  int best = -1;
  for (int i = 0; i <= n; ++i) {
    const PiAt pi = PiForMargin(gr[i], theta[i], pm, f[i], dt_s);
    if (!(pi.kp >= 0.0 && pi.ki > 0.0) || (best >= 0 && pi.ki <= d.ki)) continue;
    double peak = 0.0;
    for (int j = 0; j <= n && peak <= max_s; ++j) {
      peak = std::max(peak, 1.0 / std::abs(1.0 + std::complex<double>(pi.kp, -pi.ki * hint[j]) * gr[j]));
    }
    if (peak > max_s) continue;
    best = i;
    d.kp = pi.kp;
    d.ki = pi.ki;
    d.pi_crossover_hz = f[i];
  }
  if (best < 0) {
    throw Error("pi_lead", fmt::format("no PI gives the design model a {:g} deg phase margin with a peak sensitivity "
                                       "of at most {:g} dB",
                                       d.target_pm_deg, d.max_sensitivity_db));
  }
}

/// The PI loop as it runs (Tustin at dt, u = C (r - y)), analysed on the design model; its lag at
/// lag_hz [s]. Throws rths::Error unless it has one stable crossover with the margin.
double CheckPiLoop(const control::DiscreteSs& g, double dt_s, PiLeadDesign* out) {
  PiLeadDesign& d = *out;
  const control::ControllerLti pi_lin = Linearized(PiLeadLti(d.kp, d.ki, false, 0, 0, 0), dt_s);
  const control::LoopAnalysis loop = control::AnalyzeLoop(pi_lin.fb, g);
  d.pi_stable = loop.stable;
  d.pi_spectral_radius = loop.spectral_radius;
  d.pi_crossovers = static_cast<int>(loop.crossovers.size());
  d.pi_phase_margin_deg = loop.critical.phase_margin_deg;
  d.pi_delay_margin_ms = 1e3 * loop.critical.delay_margin_s;
  d.pi_peak_sensitivity_db = loop.peak_sensitivity_db;
  if (!loop.stable || loop.crossovers.size() != 1 || std::abs(d.pi_phase_margin_deg - d.target_pm_deg) > 0.5 ||
      d.pi_peak_sensitivity_db > d.max_sensitivity_db + 0.05) {
    throw Error("pi_lead", fmt::format("the PI (Kp {:.6g}, Ki {:.6g}) does not give one stable crossover with a "
                                       "{:g} deg margin on the design model: {} crossover(s), margin {:.2f} deg, "
                                       "peak sensitivity {:.2f} dB, spectral radius {:.6f}",
                                       d.kp, d.ki, d.target_pm_deg, loop.crossovers.size(), d.pi_phase_margin_deg,
                                       d.pi_peak_sensitivity_db, loop.spectral_radius));
  }
  const double lag_s = control::TrackingLagS(pi_lin, g, d.lag_hz);
  d.pi_lag_ms = 1e3 * lag_s;
  return lag_s;
}

}  // namespace

PiLeadDesign DesignPiLead(const models::ServoModel3& model, double dt_s) {
  PiLeadDesign d;
  d.model = model;
  d.dt_s = dt_s;
  const control::DiscreteSs g = control::ServoZoh(model, dt_s);
  ChoosePi(g, dt_s, &d);
  const double lag_s = CheckPiLoop(g, dt_s, &d);

  // (2) The lead, with the benchmark's formulas; Tl from the PI loop's lag.
  d.phi_deg = d.pi_phase_margin_deg + d.safety_deg;
  const double s = std::sin(d.phi_deg * kDeg);
  d.a = (1.0 + s) / (1.0 - s);
  d.tl_s = lag_s / (d.a - 1.0 / d.fac);
  d.w_m_rad_s = 1.0 / (d.tl_s * std::sqrt(d.a));
  const double pole0 = -1.0 / d.tl_s;
  d.zero = pole0 / d.a;
  d.pole = pole0 * d.fac;
  d.k = d.a * d.fac;

  d.controller.kind = control::ControllerKind::kLti;
  d.controller.lti = PiLeadLti(d.kp, d.ki, true, d.k, d.zero, d.pole);
  const control::ControllerLti lin = Linearized(d.controller.lti, dt_s);
  for (double f : {1.0, 5.0, 10.0, 15.0}) {
    d.check_hz.push_back(f);
    d.gyr_magnitude.push_back(std::abs(control::TrackingResponse(lin, g, f)));
    d.gyr_lag_ms.push_back(1e3 * control::TrackingLagS(lin, g, f));
  }
  return d;
}

std::string PiLeadDesign::Describe() const {
  std::string t;
  t += fmt::format("pi_lead, designed on the {} model (K {:g}, p {:g}, b {:g}, c {:g}; ZOH at {:g} ms):\n", model.name,
                   model.K, model.p, model.b, model.c, 1e3 * dt_s);
  t += fmt::format("  PI C(s) = Kp + Ki/s: the largest Ki with a {:g} deg phase margin and a peak sensitivity <= {:g} dB "
                   "(Tustin PI, ZOH model): Kp = {:.6g}, Ki = {:.6g} 1/s; crossover {:.2f} Hz, margin {:.2f} deg "
                   "({:.2f} ms of delay), peak sensitivity {:.2f} dB, {} crossover, closed loop {} (spectral radius "
                   "{:.5f})\n",
                   target_pm_deg, max_sensitivity_db, kp, ki, pi_crossover_hz, pi_phase_margin_deg, pi_delay_margin_ms,
                   pi_peak_sensitivity_db, pi_crossovers, pi_stable ? "stable" : "UNSTABLE", pi_spectral_radius);
  t += fmt::format("  the PI loop's lag at {:g} Hz: {:.3f} ms (the plant alone: 1/p + b/c + dt/2 = {:.3f} ms)\n", lag_hz,
                   pi_lag_ms, 1e3 * (1.0 / model.p + model.b / model.c + dt_s / 2));
  t += fmt::format("  lead T(s) = k (s - zero)/(s - pole): phi = margin + {:g} deg = {:.2f} deg, a = (1 + sin phi)/(1 - "
                   "sin phi) = {:.4f}, Tl = lag / (a - 1/fac) = {:.5g} ms (fac {:g}), w_m = 1/(Tl sqrt a) = {:.1f} rad/s; "
                   "zero = -1/(a Tl) = {:.5g} 1/s, pole = -fac/Tl = {:.5g} 1/s, k = a fac = {:.5g}\n",
                   safety_deg, phi_deg, a, 1e3 * tl_s, fac, w_m_rad_s, zero, pole, k);
  t += "  G_yr on the design model:";
  for (std::size_t i = 0; i < check_hz.size(); ++i) {
    t += fmt::format(" {:g} Hz |G| {:.4f} lag {:.3f} ms;", check_hz[i], gyr_magnitude[i], gyr_lag_ms[i]);
  }
  t.back() = '\n';
  t += fmt::format("  [controller.lti] feedback = {{ num = [{:.17g}, {:.17g}], den = [1.0, 0.0] }}, reference = {{ num = "
                   "[{:.17g}, {:.17g}], den = [1.0, {:.17g}] }}, domain = \"s\", discretisation = \"tustin\"\n",
                   kp, ki, k, -k * zero, -pole);
  return t;
}

}  // namespace rths::studies
