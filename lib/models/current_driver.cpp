#include "models/current_driver.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

using cd = std::complex<double>;

CurrentDriver CurrentDriver::Make(const CurrentDriverParams& p, double dt_s) {
  const auto bad = [](const char* field, double v, const char* range) {
    return Error(fmt::format("CurrentDriver: {}", field),
                 fmt::format("must be finite and {} (got {})", range, v));
  };
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (p.kind == CurrentFilter::kFirstOrder) {
    if (!positive(p.eta_1_s)) throw bad("eta_1_s", p.eta_1_s, "> 0");
    if (!positive(dt_s)) throw bad("dt_s", dt_s, "> 0");
    // H(s) = eta / (s + eta): the real mode alone; the complex pair is kept with residue 0 (and a
    // pole of its own, so Hold()'s division stays defined) and so never reaches i_c.
    CurrentDriver d;
    d.params = p;
    d.dt_s = dt_s;
    d.pole1 = -p.eta_1_s;
    d.residue1 = p.eta_1_s;
    d.pole = cd(-p.eta_1_s, p.eta_1_s);
    d.residue = cd(0.0, 0.0);
    d.phi1 = std::exp(-p.eta_1_s * dt_s);
    d.phi = std::exp(d.pole * dt_s);
    return d;
  }
  if (!positive(p.lag_pole_rad_s)) throw bad("lag_pole_rad_s", p.lag_pole_rad_s, "> 0");
  if (!positive(p.lag_zero_rad_s) || p.lag_zero_rad_s == p.lag_pole_rad_s)
    throw bad("lag_zero_rad_s", p.lag_zero_rad_s, "> 0 and != lag_pole_rad_s");
  if (!positive(p.lowpass_hz)) throw bad("lowpass_hz", p.lowpass_hz, "> 0");
  if (!(std::isfinite(p.lowpass_zeta) && p.lowpass_zeta > 0.0 && p.lowpass_zeta < 1.0))
    throw bad("lowpass_zeta", p.lowpass_zeta, "in (0, 1)");
  if (!positive(dt_s)) throw bad("dt_s", dt_s, "> 0");

  CurrentDriver d;
  d.params = p;
  d.dt_s = dt_s;
  const double a = p.lag_pole_rad_s, b = p.lag_zero_rad_s;
  const double wn = 2.0 * std::numbers::pi * p.lowpass_hz, z = p.lowpass_zeta;
  d.pole1 = -a;
  d.pole = cd(-z * wn, wn * std::sqrt(1.0 - z * z));
  const auto lowpass = [&](cd s) { return wn * wn / (s * s + 2.0 * z * wn * s + wn * wn); };
  // Residues of H(s) = (a/b)(s + b)/(s + a) LP(s): at -a, a (1 - a/b) LP(-a); at lambda,
  // (a/b)(lambda + b)/(lambda + a) w_n^2 / (lambda - conj(lambda)).
  d.residue1 = (a * (1.0 - a / b) * lowpass(cd(-a, 0.0))).real();
  const cd l = d.pole;
  d.residue = (a / b) * (l + b) / (l + a) * (wn * wn) / (l - std::conj(l));
  d.phi1 = std::exp(-a * dt_s);
  d.phi = std::exp(l * dt_s);
  return d;
}

std::complex<double> CurrentDriver::FrequencyResponse(double f_hz) const {
  const cd s(0.0, 2.0 * std::numbers::pi * f_hz);
  return residue1 / (s - pole1) + residue / (s - pole) + std::conj(residue) / (s - std::conj(pole));
}

double CurrentDriver::DcGain() const {
  return residue1 / -pole1 + 2.0 * (residue / -pole).real();
}

CurrentDriverState SteadyState(double i_A) { return {i_A, 0.0, cd(0.0, 0.0)}; }

bool AtSteadyState(const CurrentDriverState& s) {
  return s.e1_A_s == 0.0 && s.eq_A_s.real() == 0.0 && s.eq_A_s.imag() == 0.0;
}

CurrentDriverState StartState(const CurrentDriverParams& p, double i_first_A) {
  return SteadyState(p.start == CurrentStart::kRest ? 0.0 : i_first_A);
}

void Hold(const CurrentDriver& d, CurrentDriverState* s, double i_cmd_A) {
  if (i_cmd_A == s->held_A) return;  // same hold: nothing to re-express (keeps e = 0 exact)
  const double delta = i_cmd_A - s->held_A;
  // x = e + x_ss(i_h) with x_ss(i) = (i / a, -i / lambda): keep x, move the reference.
  s->e1_A_s -= delta / -d.pole1;
  s->eq_A_s += delta / d.pole;
  s->held_A = i_cmd_A;
}

double EffectiveCurrentAt(const CurrentDriver& d, const CurrentDriverState& s, double tau_s) {
  if (AtSteadyState(s)) return s.held_A;
  const double m1 = s.e1_A_s * std::exp(d.pole1 * tau_s);
  const cd q = s.eq_A_s * std::exp(d.pole * tau_s);
  return s.held_A + d.residue1 * m1 + 2.0 * (d.residue * q).real();
}

void Advance(const CurrentDriver& d, CurrentDriverState* s) {
  s->e1_A_s *= d.phi1;
  s->eq_A_s *= d.phi;
  // A deviation whose whole contribution to i_c is below kSettledA is the steady state: set it
  // to 0 so a held current becomes exactly constant again (about 11 s after a 2.5 A step)
  // instead of decaying through denormals for ever.
  if (std::abs(d.residue1 * s->e1_A_s) + 2.0 * std::abs(d.residue * s->eq_A_s) < kSettledA) {
    s->e1_A_s = 0.0;
    s->eq_A_s = cd(0.0, 0.0);
  }
}

void Step(const CurrentDriver& d, CurrentDriverState* s, double i_cmd_A) {
  Hold(d, s, i_cmd_A);
  Advance(d, s);
}

double EffectiveCurrentA(const CurrentDriver& d, const CurrentDriverState& s) {
  if (AtSteadyState(s)) return s.held_A;
  return s.held_A + d.residue1 * s.e1_A_s + 2.0 * (d.residue * s.eq_A_s).real();
}

double DriverOutputA(const CurrentDriver& d, const CurrentDriverState& s) {
  if (d.params.kind == CurrentFilter::kFirstOrder) return EffectiveCurrentA(d, s);
  const double a = d.params.lag_pole_rad_s, b = d.params.lag_zero_rad_s;
  return s.held_A + a * (1.0 - a / b) * s.e1_A_s;
}

}  // namespace rths::models
